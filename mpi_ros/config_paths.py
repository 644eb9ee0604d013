"""Where the files under config/ are: installed under share/mpi_ros/config, or in the source tree.

Light on purpose (no yaml, no controller): a one-shot verb looks up its DDS profile here
before it imports anything else (mpi_ros.dds_profile).
"""

from __future__ import annotations

import sys
from pathlib import Path


def candidates(name: str) -> list[Path]:
    """The places config/<name> may be, in the order they are tried."""
    places = [Path(sys.prefix) / "share" / "mpi_ros" / "config" / name]
    try:
        from ament_index_python.packages import get_package_share_directory

        places.insert(0, Path(get_package_share_directory("mpi_ros")) / "config" / name)
    except Exception:  # noqa: BLE001 - no ament index (plain venv): fall back below
        pass
    places.append(Path(__file__).resolve().parent.parent / "config" / name)
    return places


def find(name: str) -> Path | None:
    """config/<name>, or None where none of the candidates is a file."""
    return next((place for place in candidates(name) if place.is_file()), None)
