"""One module per CLI verb: ``HELP``, ``configure(parser)``, ``run(args) -> int``; a verb's helpers
that are a concern of their own sit beside it as ``<verb>_<concern>.py`` (``hold_io``)."""
