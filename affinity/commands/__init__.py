"""One module per subcommand: each has ``add_parser(subparsers)`` and ``run(args) -> exit code``.

Subcommands import what they need inside ``run``, so ``affinity check`` pays
for NumPy and nothing heavier.
"""

EXIT_CLEAN, EXIT_FINDINGS, EXIT_ERROR = 0, 1, 2
