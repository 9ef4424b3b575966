import sys

from vcc.cli import main

sys.exit(main())
