"""Resolve: a launch description, arguments and environment become a Plan; nothing is spawned.

``resolver`` visits the description; ``binding`` compares values captured where timers and
handlers were written with those when they fire; ``describe`` and ``plan_json`` write a plan
(``--print``)."""
