"""One module per ``rsg`` verb, each with ``add_parser(subparsers)`` and ``run(args)``;
the options they share are in :mod:`app.commands.arguments`."""
