"""launch_pytest example written for mlaunch: one module-scoped launch per parameter, shared by
the tests, shut down after the last of them; the order things ran in is checked at the end."""

import os
import sys

import launch
import launch.actions
import launch_pytest
import pytest

CHATTER = os.path.join(os.path.dirname(__file__), "..", "launch_testing", "chatter.py")
ORDER = []


@launch_pytest.fixture(scope="module", params=["one", "two"])
def shared(request):
    action = launch.actions.ExecuteProcess(
        cmd=[sys.executable, CHATTER, "--count", "1", request.param], cached_output=True
    )
    return launch.LaunchDescription([action, launch_pytest.actions.ReadyToTest()]), action


@pytest.mark.launch(fixture=shared, shutdown=True)
def test_after(shared, launch_service):
    ORDER.append(f"after {shared[1].process_details['cmd'][-1]}")
    assert launch_service._is_idle()


@pytest.mark.launch(fixture=shared)
def test_hello(shared):
    # No wait_for_start here: in ROS 2 it waits for the next start, which a launch shared by
    # several tests may have had already.
    word = shared[1].process_details["cmd"][-1]
    ORDER.append(f"hello {word}")
    yield
    ORDER.append(f"end {word}")


def test_order():
    assert ORDER == ["hello one", "after one", "end one", "hello two", "after two", "end two"]
