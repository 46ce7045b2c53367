import sys

from drake_biped.cli import main

sys.exit(main())
