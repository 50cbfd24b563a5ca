"""The `splatgl` console script: the same command as the Rust binary, run in-process."""

import sys

from . import _splatgl


def main() -> None:
    sys.exit(_splatgl.cli(["splatgl", *sys.argv[1:]]))


if __name__ == "__main__":
    main()
