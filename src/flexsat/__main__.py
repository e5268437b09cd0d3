"""``python -m flexsat`` runs the command line."""

from flexsat.cli.main import main

main()
