"""Every private rclpy binding the suite uses, in one place, and the rclpy it was written for.

The batched action server (goal_server.py, goal_endpoints.py, goal_loop.py, goal_front.py)
waits on and takes from the action's services itself, which rclpy's public API does not
offer: it uses rclpy's C bindings (``rclpy.impl.implementation_singleton``) for services,
guard conditions and wait sets. Those bindings are not a stable interface; they change
between ROS releases. So nothing else imports them: this module makes each object, and
:func:`check_version` refuses an rclpy other than the one they were written for, naming
it, before any node is made. ``ros.action_server: rclpy`` (docs/reliability.md) serves
goals with rclpy's stock ActionServer instead, which needs none of this.
"""

from __future__ import annotations

import importlib.metadata
from typing import Any

from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy

# The bindings' own error (rclpy._rclpy_pybind11.RCLError): raised when the context shut down
# under a wait, or a response could not be sent.
RCLError: type[Exception] = _rclpy.RCLError

# rclpy 7.1 is ROS 2 Jazzy's; its private bindings are what this module was written against.
SUPPORTED = ((7, 1),)


class UnsupportedRclpy(RuntimeError):
    """The installed rclpy is not one the batched action server was written for."""


def rclpy_version() -> str:
    return importlib.metadata.version("rclpy")


def check_version(version: str | None = None) -> None:
    """Refuse an rclpy whose private bindings may differ from those used here."""
    found = rclpy_version() if version is None else version
    try:
        major_minor = tuple(int(part) for part in found.split(".")[:2])
    except ValueError:
        major_minor = ()
    if major_minor not in SUPPORTED:
        written_for = ", ".join(f"{major}.{minor}" for major, minor in SUPPORTED)
        raise UnsupportedRclpy(
            f"rclpy {found} is installed, but the batched action server uses rclpy's private bindings as of "
            f"rclpy {written_for} (ROS 2 Jazzy). Set ros.action_server: rclpy to serve goals with rclpy's own "
            "ActionServer, or install the rclpy of ROS 2 Jazzy.")


def service(node_handle: Any, service_type: Any, name: str, qos: Any) -> Any:
    """An rcl service on a node (its C handle held by the caller), taken from directly."""
    return _rclpy.Service(node_handle, service_type, name, qos.get_c_qos_profile())


def guard_condition(context_handle: Any) -> Any:
    """A guard condition of a context (its C handle held by the caller)."""
    return _rclpy.GuardCondition(context_handle)


def wait_set(services: int, context_handle: Any) -> Any:
    """A wait set for one guard condition and ``services`` services."""
    return _rclpy.WaitSet(0, 1, 0, 0, services, 0, context_handle)
