"""Child process for test_cross_process.py: serves mpi_ros endpoints over DDS.

Serves, under the contract's names:
- action  /mpi/ms0/motion_start (mpi_ros/action/MotionStart): accepts the goal, publishes
  feedback every 20 ms until a MotionAction request arrives (so the client surely sees feedback,
  however late its feedback subscription matches), then succeeds with a result that echoes the
  goal's positions;
- service /mpi/ms0/action (mpi_ros/srv/MotionAction): answers MPIMessageOK and ends the goal;
- topic   /mpi/axis0/status (mpi_ros/msg/AxisStatus): published at 20 Hz.
Prints READY once everything exists; exits with status 0 when its stdin closes (or on SIGTERM).
Not a test module (no test_ prefix); run as `python -P dds_peer.py`.
"""

from __future__ import annotations

import signal
import sys
import threading

import rclpy
from rclpy.action import ActionServer, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor

from mpi_ros.action import MotionStart
from mpi_ros.msg import AxisStatus
from mpi_ros.srv import MotionAction


def main() -> int:
    stop = threading.Event()
    end_goal = threading.Event()
    context = rclpy.Context()
    rclpy.init(context=context)
    node = rclpy.create_node("dds_peer", namespace="/mpi", context=context)
    group = ReentrantCallbackGroup()  # a mutually exclusive group can make MTE busy-loop

    def execute(goal_handle):
        goal = goal_handle.request
        feedback = MotionStart.Feedback()
        feedback.state_name = "MOVING"
        feedback.command_position = [float(p) for p in goal.position]
        n = 0
        while not end_goal.is_set() and not stop.is_set() and n < 1500:  # <= 30 s
            feedback.progress = min(1.0, n / 100.0)
            feedback.element_id = n
            goal_handle.publish_feedback(feedback)
            n += 1
            end_goal.wait(0.02)
        result = MotionStart.Result()
        result.message = "MPIMessageOK"
        result.code = 0
        result.state = AxisStatus.STATE_IDLE
        result.state_name = "IDLE"
        result.actual_position = [float(p) for p in goal.position]
        result.detail = f"{goal.type} with {len(goal.trajectory)} trajectory element(s)"
        if end_goal.is_set():
            goal_handle.succeed()
        else:
            goal_handle.abort()
        return result

    def action_service(request, response):
        response.message = "MPIMessageOK"
        response.code = 0
        response.state = AxisStatus.STATE_STOPPING
        response.state_name = f"after {request.action}"
        response.sample = 42
        end_goal.set()
        return response

    sample = [0]
    publisher = node.create_publisher(AxisStatus, "axis0/status", 10)

    def publish_status():
        sample[0] += 1
        msg = AxisStatus()
        msg.sample = sample[0]
        msg.number = 0
        msg.state = AxisStatus.STATE_IDLE
        msg.state_name = "IDLE"
        msg.command_position = 12.5
        publisher.publish(msg)

    server = ActionServer(node, MotionStart, "ms0/motion_start", execute_callback=execute,
                          goal_callback=lambda _goal: GoalResponse.ACCEPT,
                          callback_group=group)
    service = node.create_service(MotionAction, "ms0/action", action_service,
                                  callback_group=group)
    timer = node.create_timer(0.05, publish_status, callback_group=group)

    def watch_stdin():
        sys.stdin.read()  # returns at EOF: the parent closed our stdin
        stop.set()

    threading.Thread(target=watch_stdin, daemon=True).start()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())

    executor = MultiThreadedExecutor(num_threads=2, context=context)
    executor.add_node(node)
    print("READY", flush=True)
    try:
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.1)
    finally:
        executor.shutdown(timeout_sec=5.0)
        timer.destroy()
        server.destroy()
        node.destroy_service(service)
        node.destroy_node()
        context.try_shutdown()
    print("BYE", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
