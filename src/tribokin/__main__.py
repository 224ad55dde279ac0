import sys

from tribokin.cli import main

sys.exit(main())
