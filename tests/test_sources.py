"""scripts/sources.py: upstream sources by repository and commit, checked against pinned content
(what `scripts/setup --real-nodes` and `--ros1-sources` use without a folder). A server on
127.0.0.1 plays the repository host; the pins in the repository are checked against CI's copy of
the archives where it is there."""

from __future__ import annotations

import csv
import hashlib
import http.server
import io
import subprocess
import sys
import tarfile
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from procutil import REPO

sys.path.insert(0, str(REPO / "scripts"))
import sources

COMMIT = "0123456789abcdef0123456789abcdef01234567"
# The pins (scripts/sources-NAME.tsv) -> CI's copy of the same archives.
CI_SOURCES = {
    "ros2": REPO.parent / "shared" / "ros2-src",
    "ros1": REPO.parent / "shared" / "ros1-src",
}


def repo_tarball(files: dict[str, str]) -> bytes:
    """A repository's tarball as a forge serves it: one top folder NAME-COMMIT."""
    out = io.BytesIO()
    with tarfile.open(fileobj=out, mode="w:gz") as tar:
        for name, text in files.items():
            data = text.encode()
            info = tarfile.TarInfo(f"demo-{COMMIT}/{name}")
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
    return out.getvalue()


class Forge:
    """Serves /OWNER/REPO/archive/COMMIT.tar.gz from a dict, and counts what was asked."""

    def __init__(self) -> None:
        self.tarballs: dict[str, bytes] = {}
        self.requests: list[str] = []
        forge = self

        class Handler(http.server.BaseHTTPRequestHandler):
            def do_GET(self) -> None:
                forge.requests.append(self.path)
                body = forge.tarballs.get(self.path)
                self.send_response(200 if body is not None else 404)
                self.end_headers()
                self.wfile.write(body or b"")

            def log_message(self, *args: object) -> None:
                pass

        self.server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        threading.Thread(target=self.server.serve_forever, daemon=True).start()
        self.url = f"http://127.0.0.1:{self.server.server_address[1]}"


@pytest.fixture
def forge() -> Iterator[Forge]:
    served = Forge()
    try:
        yield served
    finally:
        served.server.shutdown()
        served.server.server_close()


def pins(tmp: Path, content: str, paths: str = "pkg LICENSE") -> Path:
    path = tmp / "sources.tsv"
    path.write_text(
        "archive\trepo\tref\tcommit\tpaths\tcontent\n"
        f"demo.tar.gz\towner/demo\tmain\t{COMMIT}\t{paths}\t{content}\n"
    )
    return path


FILES = {"pkg/package.xml": "<package/>", "pkg/src/a.cpp": "int a;", "LICENSE": "L", "x/y": "no"}


def expected_content(tmp: Path) -> str:
    folder = tmp / "expected" / "demo"
    for name in ("pkg/package.xml", "pkg/src/a.cpp", "LICENSE"):
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(FILES[name])
    return sources.content_digest(folder)


def test_fetch_keeps_the_pinned_paths_checks_them_and_downloads_once(
    tmp_path: Path, forge: Forge
) -> None:
    forge.tarballs[f"/owner/demo/archive/{COMMIT}.tar.gz"] = repo_tarball(FILES)
    dest = tmp_path / "dest"
    content = expected_content(tmp_path)
    got = sources.fetch(pins(tmp_path, content), dest, forge.url)
    assert got == dest and len(forge.requests) == 1
    with tarfile.open(dest / "demo.tar.gz") as tar:
        names = sorted(tar.getnames())
    assert names == ["demo", "demo/LICENSE", "demo/pkg", "demo/pkg/package.xml", "demo/pkg/src",
                     "demo/pkg/src/a.cpp"]  # fmt: skip
    assert sources.archive_content(dest / "demo.tar.gz") == content
    with (dest / "MANIFEST.tsv").open() as handle:
        row = next(csv.DictReader(handle, delimiter="\t"))
    assert row["commit"] == COMMIT and row["paths"] == "pkg LICENSE"
    assert row["sha256"] == hashlib.sha256((dest / "demo.tar.gz").read_bytes()).hexdigest()
    # A second setup finds the archive with its pinned content and downloads nothing.
    first = (dest / "demo.tar.gz").read_bytes()
    sources.fetch(pins(tmp_path, content), dest, forge.url)
    assert len(forge.requests) == 1 and (dest / "demo.tar.gz").read_bytes() == first


def test_content_that_is_not_the_pinned_one_is_refused(tmp_path: Path, forge: Forge) -> None:
    content = expected_content(tmp_path)
    forge.tarballs[f"/owner/demo/archive/{COMMIT}.tar.gz"] = repo_tarball(
        {**FILES, "pkg/src/a.cpp": "int b;"}
    )
    with pytest.raises(sources.SourcesError) as caught:
        sources.fetch(pins(tmp_path, content), tmp_path / "dest", forge.url)
    message = str(caught.value)
    assert f"demo.tar.gz: owner/demo at {COMMIT} does not hold the pinned content" in message
    assert "refusing to build from it" in message
    assert not (tmp_path / "dest/demo.tar.gz").exists()


def test_a_missing_path_or_commit_is_said(tmp_path: Path, forge: Forge) -> None:
    forge.tarballs[f"/owner/demo/archive/{COMMIT}.tar.gz"] = repo_tarball(FILES)
    with pytest.raises(sources.SourcesError, match="the repository has no 'docs' at this commit"):
        sources.fetch(pins(tmp_path, "0" * 64, "pkg docs"), tmp_path / "d1", forge.url)
    forge.tarballs.clear()
    with pytest.raises(sources.SourcesError, match=r"cannot download http://127\.0\.0\.1:\d+/"):
        sources.fetch(pins(tmp_path, "0" * 64), tmp_path / "d2", forge.url)
    bad = tmp_path / "bad.tsv"
    bad.write_text("archive\trepo\tref\tcommit\tpaths\tcontent\ndemo.tar.gz\towner/demo\t\t\t.\t\n")
    with pytest.raises(sources.SourcesError, match=r"bad.tsv:2: no ref, commit, content"):
        sources.read_pins(bad)


def test_the_command_line_says_one_line_on_failure(tmp_path: Path, forge: Forge) -> None:
    script = REPO / "scripts/sources.py"
    done = subprocess.run(
        [sys.executable, str(script), "fetch", str(pins(tmp_path, "0" * 64)), str(tmp_path / "d")],
        capture_output=True,
        text=True,
        timeout=60,
        env={"MLAUNCH_SOURCES_URL": forge.url, "PATH": "/usr/bin:/bin"},
    )
    assert done.returncode == 1
    assert done.stderr.splitlines()[-1].startswith("sources: cannot download ")


@pytest.mark.parametrize("name", sorted(CI_SOURCES))
def test_the_pins_match_the_archives_ci_builds_from(name: str) -> None:
    ci = CI_SOURCES[name]
    if not (ci / "MANIFEST.tsv").is_file():
        pytest.skip(f"no copy of the source archives beside the clone ({ci})")
    pinned = sources.read_pins(REPO / "scripts" / f"sources-{name}.tsv")
    with (ci / "MANIFEST.tsv").open(newline="") as handle:
        manifest = {r["archive"]: r for r in csv.DictReader(handle, delimiter="\t")}
    assert sorted(p["archive"] for p in pinned) == sorted(manifest)
    for pin in pinned:
        row = manifest[pin["archive"]]
        assert (pin["repo"], pin["commit"], pin["paths"]) == (
            row["repo"],
            row["commit"],
            row["paths"],
        )
        assert sources.archive_content(ci / pin["archive"]) == pin["content"], pin["archive"]


def git_clone_of(tmp: Path, files: dict[str, str]) -> tuple[Path, str]:
    """A bare clone named OWNER+REPO (one layout --git takes) holding ``files`` in one commit."""
    work = tmp / "work"
    for name, text in files.items():
        (work / name).parent.mkdir(parents=True, exist_ok=True)
        (work / name).write_text(text)
    env = {"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t", "GIT_COMMITTER_NAME": "t",
           "GIT_COMMITTER_EMAIL": "t@t", "PATH": "/usr/bin:/bin", "HOME": str(tmp)}  # fmt: skip
    for step in (["init", "-q"], ["add", "."], ["commit", "-qm", "one"]):
        subprocess.run(["git", "-C", str(work), *step], check=True, env=env)
    commit = subprocess.run(["git", "-C", str(work), "rev-parse", "HEAD"], capture_output=True,
                            text=True, check=True).stdout.strip()  # fmt: skip
    mirrors = tmp / "mirrors"
    subprocess.run(["git", "clone", "-q", "--bare", str(work), str(mirrors / "owner+demo" / "repo")],
                   check=True, env=env)  # fmt: skip
    return mirrors, commit


def test_fetch_takes_the_pinned_paths_from_a_git_clone(tmp_path: Path) -> None:
    mirrors, commit = git_clone_of(tmp_path, FILES)
    content = expected_content(tmp_path)
    pin = pins(tmp_path, content, "pkg/package.xml pkg/src LICENSE")  # a file inside a folder too
    pin.write_text(pin.read_text().replace(COMMIT, commit))
    dest = sources.fetch(pin, tmp_path / "dest", "http://127.0.0.1:9/unused", mirrors)
    assert sources.archive_content(dest / "demo.tar.gz") == content
    with tarfile.open(dest / "demo.tar.gz") as tar:
        assert "demo/x/y" not in tar.getnames()  # only the pinned paths
    # A commit the clone lacks, or no clone of the repository, is said.
    pin.write_text(pin.read_text().replace(commit, "f" * 40))
    with pytest.raises(sources.SourcesError, match=f"git archive of {'f' * 40} in .*owner"):
        sources.fetch(pin, tmp_path / "d2", "http://127.0.0.1:9/unused", mirrors)
    with pytest.raises(sources.SourcesError, match="no git clone of owner/demo in"):
        sources.fetch(pin, tmp_path / "d3", "http://127.0.0.1:9/unused", tmp_path / "none")
