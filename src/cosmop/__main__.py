"""``python -m cosmop``: the command line."""

from cosmop.cli import main

if __name__ == "__main__":
    main()
