"""mpi_ros: a ROS 2 Jazzy node suite for MPI/XMP-style motion controllers.

Each motion supervisor is a ROS 2 node (MotionStart/MotionModify actions, MPI actions as
services, axis and motion status topics) in front of a faithful simulated controller.

Subpackages: ``mpi_ros.mpi`` (the simulated controller, no rclpy), ``mpi_ros.ros`` (the nodes),
``mpi_ros.cli`` (the ``mpi-ros`` command), and the generated interfaces ``mpi_ros.msg``,
``mpi_ros.srv`` and ``mpi_ros.action`` (present only in an installed package, not in the
source tree). Importing this package must stay cheap: it does not import rclpy.
"""

__version__ = "0.1.0"

# The generated interfaces (mpi_ros.msg/.srv/.action and their typesupport libraries) exist
# only in an installed package. When this source tree is first on sys.path (pytest or python
# run from the repository root), let the package span both folders: the source's modules win,
# the installed package supplies the generated ones.
from pkgutil import extend_path

__path__ = extend_path(__path__, __name__)
