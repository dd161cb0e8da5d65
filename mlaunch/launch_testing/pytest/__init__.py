"""launch_testing's pytest plugin (``hooks``) and the hook it adds (``hookspecs``)."""
