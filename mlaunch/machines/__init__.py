"""Several machines, as a launch file writes them (``Machine``, ``PushMachine``, ``machine=``).

The resolved machine is ``mlaunch.plan.machine``; the SSH connection, the process seam and the
agent that runs on the other computer are parts of a run (``mlaunch.parts.ssh``, ``remote``,
``agent``). Nothing here is imported by a launch that declares no machine.
"""
