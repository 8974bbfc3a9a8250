"""The ``asperity`` command installed with the Python package: the command line compiled
into the extension module (``asperity._asperity.cli``), so that ``pip install ./python``
builds Rust once for both. Same commands, options, outputs and exit statuses as a
``cargo build`` of ``asperity-cli``."""

import sys


def main() -> None:
    from . import _asperity

    sys.exit(_asperity.cli(["asperity", *sys.argv[1:]]))


if __name__ == "__main__":
    main()
