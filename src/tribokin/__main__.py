import sys

from tribokin.cli import entry

sys.exit(entry())
