"""``python -m teamnav``: the same as the ``teamnav`` command."""

from teamnav.cli import main

if __name__ == "__main__":
    main()
