"""One module per subcommand: each has ``add_parser(subparsers)`` and ``run(args) -> exit code``.

Subcommands import what they need inside ``run``, so ``affinity check`` pays
for NumPy and nothing heavier.
"""

EXIT_CLEAN, EXIT_FINDINGS, EXIT_ERROR = 0, 1, 2


def spelling(text: str) -> str:
    """An argparse ``type`` for attribute names: ``color`` everywhere, ``colour`` accepted."""
    return "color" if text == "colour" else text


def require(modules: tuple[str, ...], extra: str) -> None:
    """Stop with one line naming the missing modules and the extra that installs them.

    Raises ``affinity.errors.UsageError`` (exit 2) instead of an ImportError traceback.
    """
    import importlib.util

    from ..errors import UsageError

    missing = [name for name in modules if importlib.util.find_spec(name) is None]
    if missing:
        raise UsageError(f"needs {', '.join(missing)}, the {extra} extra: pip install 'quad-affinity[{extra}]'")
