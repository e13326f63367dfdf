"""``python -m toposmooth ARGS`` and the ``toposmooth`` console script: the command-line tool,
the same as the Rust binary (``toposmooth --help``)."""

import sys

from . import _toposmooth


def main() -> None:
    sys.exit(_toposmooth.main(["toposmooth", *sys.argv[1:]]))


if __name__ == "__main__":
    main()
