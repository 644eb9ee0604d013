"""Launch a machine: the mpi_ros suite and, where the ROS install has them,
robot_state_publisher and RViz.

  ros2 launch mpi_ros machine.launch.py config:=/path/to/gantry.yaml [namespace:=/cell_a]
      [record:=BAG] [rviz:=true]

Arguments:
  config     the suite's YAML configuration (default: share/mpi_ros/config/gantry.yaml)
  namespace  the suite's namespace (default: the configuration's ros.namespace, /mpi)
  record     a bag directory to record the run to (default: none)
  rviz       true: start RViz, fixed frame the machine's base_link (default: false)

robot_state_publisher runs in the suite's namespace with the suite's robot description (the
one `mpi-ros urdf` prints and the suite latches on <ns>/robot_description: both publish the
same text there) and reads the suite's joint states (/joint_states for /mpi, else
<ns>/joint_states; docs/cell.md). It broadcasts every link on /tf. A package missing from the
install (robot_state_publisher, rviz2) is skipped with a message; the suite starts anyway.
"""

import os

from ament_index_python.packages import PackageNotFoundError, get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, LogInfo, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from mpi_ros import description


def _installed(package):
    try:
        get_package_share_directory(package)
    except PackageNotFoundError:
        return False
    return True


def _machine(context):
    """The actions, once the arguments are known: the suite's configuration decides the
    namespace, the joint states topic and the description."""
    path = LaunchConfiguration("config").perform(context)
    namespace = LaunchConfiguration("namespace").perform(context)
    record = LaunchConfiguration("record").perform(context)
    config = description.load(path, namespace or None)
    suite_args = ["--config", path]
    if namespace:
        suite_args += ["--namespace", namespace]
    if record:
        suite_args += ["--record", record]
    actions = [Node(package="mpi_ros", executable="suite", arguments=suite_args, output="screen", emulate_tty=True)]
    if _installed("robot_state_publisher"):
        actions.append(Node(
            package="robot_state_publisher", executable="robot_state_publisher", namespace=config.ros.namespace,
            parameters=[{"robot_description": description.robot_description(config)}],
            remappings=[("joint_states", config.ros.joint_states_topic)], output="screen"))
    else:
        actions.append(LogInfo(msg="robot_state_publisher is not installed: no /tf for the machine's links"))
    if LaunchConfiguration("rviz").perform(context).lower() in ("true", "1", "yes"):
        if _installed("rviz2"):
            actions.append(Node(package="rviz2", executable="rviz2", arguments=["-f", description.base_link(config)],
                                output="screen"))
        else:
            actions.append(LogInfo(msg="rviz2 is not installed: no RViz"))
    return actions


def generate_launch_description():
    default_config = os.path.join(get_package_share_directory("mpi_ros"), "config", "gantry.yaml")
    return LaunchDescription([
        DeclareLaunchArgument("config", default_value=default_config,
                              description="mpi_ros configuration file (YAML)"),
        DeclareLaunchArgument("namespace", default_value="",
                              description="the suite's namespace (empty: the configuration's ros.namespace)"),
        DeclareLaunchArgument("record", default_value="", description="record the run to this bag directory"),
        DeclareLaunchArgument("rviz", default_value="false", description="true: start RViz"),
        OpaqueFunction(function=_machine),
    ])
