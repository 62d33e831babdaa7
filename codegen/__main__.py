"""``python -m codegen`` runs the battgen command line."""

from .cli import main

raise SystemExit(main())
