"""The ROS 2 layer: thin rclpy nodes over the shared simulated controller.

suite.py builds the suite (one ControllerNode, one SupervisorNode per supervisor, one
executor); convert.py is the message <-> data edge; goal_tracker.py decides when a goal
is over. Nothing here does motion math.
"""
