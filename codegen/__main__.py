"""``python -m codegen`` runs the battgen command line."""

from .cli.main import main

raise SystemExit(main())
