import sys

from gyro.cli import main

sys.exit(main())
