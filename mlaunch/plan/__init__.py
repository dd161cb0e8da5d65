"""The plan layer, at the bottom: what every other layer shares and that imports nothing above it.

The resolved plan (``steps``: steps, ``ProcessSpec``, ``Plan``), the event records a run emits
(``events``), a resolved machine (``machine``), errors with their place (``errors``, ``origin``)
and the small ``Value`` base (``value``)."""
