"""Sub-commands of the battgen CLI beyond list / ir / generate, one module each.

Each module exposes ``register(subparsers)`` adding its parser with ``set_defaults(func=...)``;
a command function takes the parsed arguments and returns the exit code.
"""

COMMAND_MODULES: tuple[str, ...] = (
    "codegen.cli.validate",
    "codegen.cli.docs",
    "codegen.cli.schema",
    "codegen.cli.convert",
    "codegen.cli.params",
    "codegen.cli.failsafe",
)
