"""``python -m compliance`` runs the govcheck CLI."""
import sys

from .cli import main

sys.exit(main())
