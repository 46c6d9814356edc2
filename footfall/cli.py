"""The ``footfall`` command line (placeholder, filled in below)."""

import typer

app = typer.Typer(no_args_is_help=True, add_completion=False)


@app.callback()
def _root() -> None:
    """footfall: procedural locomotion of multi-legged characters."""


def main() -> None:
    app()
