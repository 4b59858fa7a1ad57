"""``python -m gearchaos``: the command-line interface (see :mod:`gearchaos.cli`)."""

from .cli import app

app(prog_name="gearchaos")
