"""``python -m cablelife`` runs the command line."""

from cablelife.cli import app

app(prog_name="cablelife")
