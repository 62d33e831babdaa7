"""Runtime of the generated converters (``convert/`` in a generated package): ``_runtime.py`` is
copied verbatim; this ``__init__`` is not (the backend writes the package's ``convert/__init__.py``).
"""
