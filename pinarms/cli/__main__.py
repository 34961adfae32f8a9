"""``python -m pinarms.cli`` runs the command line."""

from pinarms.cli import main

if __name__ == "__main__":  # pragma: no cover
    main()
