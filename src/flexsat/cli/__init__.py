"""The ``flexsat`` command line (Typer): :data:`app` and its entry point :func:`main`."""

from flexsat.cli.main import app, main

__all__ = ["app", "main"]
