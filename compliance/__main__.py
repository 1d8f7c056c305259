"""``python -m compliance`` runs the govcheck CLI."""
import sys

from compliance.cli import main

sys.exit(main())
