"""The C host (host.c) that runs a scene's FMUs without Python on top (:mod:`.native` builds and runs it)."""
