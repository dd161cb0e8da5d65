"""Export a launch to a service manager: ``systemd`` writes one unit per process under a target."""
