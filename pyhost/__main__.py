import sys

from pyhost.cli import main

sys.exit(main())
