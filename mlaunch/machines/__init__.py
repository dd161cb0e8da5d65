"""Several machines: processes of one launch started on other computers over SSH.

``spec`` is the resolved machine (what ``--print`` shows), ``actions`` the launch-file spelling
(``Machine``, ``PushMachine``, ``machine=``), ``ssh`` one multiplexed connection per machine,
``remote`` the process seam the supervisor calls, and ``agent`` the small program that runs on
the other computer. Nothing here is imported by a launch that declares no machine.
"""
