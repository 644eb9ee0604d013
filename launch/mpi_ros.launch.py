"""Launch the mpi_ros node suite: ``ros2 launch mpi_ros mpi_ros.launch.py [config:=FILE]``.

One process (the ``suite`` executable, the same as ``mpi-ros run``) hosts every node of the
suite, so no node name or namespace is remapped here: a ``__node`` remap would rename all of
them. The namespace and the rest come from the configuration file.

Arguments:
  config      the suite's YAML configuration (default: share/mpi_ros/config/default.yaml)
  time_scale  1 real time, larger is faster, 0 as fast as possible (default: 1.0)
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    default_config = os.path.join(
        get_package_share_directory("mpi_ros"), "config", "default.yaml")
    return LaunchDescription([
        DeclareLaunchArgument(
            "config", default_value=default_config,
            description="mpi_ros configuration file (YAML)"),
        DeclareLaunchArgument(
            "time_scale", default_value="1.0",
            description="1 real time, larger is faster, 0 as fast as possible"),
        Node(
            package="mpi_ros",
            executable="suite",
            arguments=[
                "--config", LaunchConfiguration("config"),
                "--time-scale", LaunchConfiguration("time_scale"),
            ],
            output="screen",
            emulate_tty=True,
        ),
    ])
