"""``python -m mpi_ros.cli``: the same as the ``mpi-ros`` command."""
import sys

from mpi_ros.cli import main

sys.exit(main())
