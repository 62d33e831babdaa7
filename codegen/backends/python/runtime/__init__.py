"""The runtime of generated packages: modules copied verbatim into every package that needs them.

Each module here is ordinary Python, linted and type-checked with the toolchain, and imports only
the standard library and its sibling runtime modules (relatively). ``<path>`` here becomes
``<path>`` in the generated package, behind a header naming its source; the codecs and extensions
name the files they need (``runtime_files``) and :func:`copied` reads them. This ``__init__`` and
the stubs (``*.pyi``, standing in for per-schema modules the backend generates) are not copied.
"""

from __future__ import annotations

from importlib import resources

SOURCE = __name__.replace(".", "/")  # where the header says a copied file comes from


def copied(*paths: str) -> dict[str, str]:
    """Path in the generated package -> text, for runtime files given by their path here."""
    root = resources.files(__name__)
    files: dict[str, str] = {}
    for path in paths:
        text = root.joinpath(*path.split("/")).read_text(encoding="utf-8")
        files[path] = f"# Copied by battgen from {SOURCE}/{path}; do not edit here, edit it there.\n" + text
    return files
