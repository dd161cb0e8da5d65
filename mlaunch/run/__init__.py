"""The engine: resolve a description into a plan, then spawn, supervise and report it."""
