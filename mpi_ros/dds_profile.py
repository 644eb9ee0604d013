"""The Fast DDS profiles the suite and the tools ship (config/fastdds_*.xml), and when they apply.

``mpi-ros run`` announces the suite every 0.1 s (config/fastdds_discovery.xml); every other
``mpi-ros`` verb gives its participant large UDP receive buffers (config/fastdds_client.xml),
so that the burst of endpoint announcements a new participant receives is not dropped
(docs/reliability.md, "How soon a one-shot verb acts"). Either is set before rclpy creates the
participant, and only where the operator chose no profile file and no other middleware. The
variable is inherited by child processes: a suite started by a tool (or by a test process
that ran a verb) sees the tools' file, which is ours, and replaces it with its own.
"""

from __future__ import annotations

from collections.abc import MutableMapping

from . import config_paths

SUITE = "fastdds_discovery.xml"
CLIENT = "fastdds_client.xml"
PROFILE_VARIABLES = ("FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE")
FAST_DDS = ("", "rmw_fastrtps_cpp", "rmw_fastrtps_dynamic_cpp")  # RMW_IMPLEMENTATION values ("" = the default)


def ours(path: str) -> bool:
    """Whether ``path`` is one of the profiles shipped here, wherever it was found (set by a
    parent process, not chosen by the operator)."""
    return any(str(place) == path for name in (SUITE, CLIENT) for place in config_paths.candidates(name))


def use(environ: MutableMapping[str, str], name: str) -> str | None:
    """Point Fast DDS at config/<name> unless the operator chose a profile file of their own or
    another middleware; returns the file set, or None. Call before the first node is created."""
    if environ.get("RMW_IMPLEMENTATION", "") not in FAST_DDS:
        return None
    if any(environ.get(v) and not ours(environ[v]) for v in PROFILE_VARIABLES):
        return None
    path = config_paths.find(name)
    if path is None:  # an installation without config/: Fast DDS's defaults, as before the profiles
        return None
    for variable in PROFILE_VARIABLES[1:]:
        environ.pop(variable, None)  # ours (checked above): the one set below decides
    environ[PROFILE_VARIABLES[0]] = str(path)
    return str(path)
