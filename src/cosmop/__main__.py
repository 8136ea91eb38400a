"""``python -m cosmop``: the command line."""

from cosmop._entry import run

if __name__ == "__main__":
    run()
