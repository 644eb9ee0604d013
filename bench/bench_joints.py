"""/joint_states' hot path: the joint conversion and the CDR packing of one message.

At every joint-states sample (100 Hz and more) the controller node converts every axis'
position, velocity and effort from counts to the joint's units and packs the message
(ros/controller_node.py: JointStates.convert, then wire.joint_state). Timed here side by side,
in one process, on the same values, the cases interleaved (each best of ``--rounds`` rounds of
``--number`` calls):

- ``counts``: no conversion (axes without a joint: what every message cost before joints);
- ``JointStates``: the suite's conversion (tuples of scales and offsets, one pass);
- ``per-axis objects``: AxisJoint.position / rate per axis, a method call per value;
- ``numpy``: one array of the three rows, scaled and offset in place, back to lists.

    python -P bench/bench_joints.py [--rounds 5] [--number 20000]
"""

from __future__ import annotations

import argparse
import timeit

import numpy as np

from mpi_ros.joints import AxisJoint, Joint, JointStates
from mpi_ros.ros import wire


def _joints(count: int) -> list[AxisJoint]:
    """Every axis a joint (a gantry's mix: metres, a reversed axis, radians)."""
    kinds = [Joint("a", "prismatic", 1e6, 0.0), Joint("b", "prismatic", -1e6, 0.3),
             Joint("c", "continuous", 1591.5494309189535, 0.0)]
    return [AxisJoint(k, f"j{k}", kinds[k % 3]) for k in range(count)]


def _cases(count: int):
    joints = _joints(count)
    names = [j.name for j in joints]
    position = [1234.5 * k for k in range(count)]
    velocity = [-50.0 * k for k in range(count)]
    effort = [3.0 * k for k in range(count)]
    states = JointStates(joints)
    plain = JointStates([AxisJoint(k, f"axis{k}", None) for k in range(count)])
    scale = np.array([[j.joint.counts_per_unit for j in joints]] * 3)  # type: ignore[union-attr]
    offset = np.array([[j.joint.offset for j in joints], [0.0] * count, [0.0] * count])  # type: ignore[union-attr]

    def pack(values) -> bytes:
        return wire.joint_state(1000, 2000.0, 0, names, *values)

    def per_axis():
        return ([j.position(p) for j, p in zip(joints, position, strict=True)],
                [j.rate(v) for j, v in zip(joints, velocity, strict=True)],
                [j.rate(e) for j, e in zip(joints, effort, strict=True)])

    def with_numpy():
        values = np.array((position, velocity, effort))
        values /= scale
        values += offset
        return values.tolist()

    return {
        "counts": lambda: pack(plain.convert(position, velocity, effort)),
        "JointStates": lambda: pack(states.convert(position, velocity, effort)),
        "per-axis objects": lambda: pack(per_axis()),
        "numpy": lambda: pack(with_numpy()),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--number", type=int, default=20000)
    args = parser.parse_args()
    print("| axes | " + " | ".join(_cases(1)) + " |")
    print("| --- |" + " --- |" * len(_cases(1)))
    for count in (4, 8, 32):
        cases = _cases(count)
        times = dict.fromkeys(cases, float("inf"))
        for _ in range(args.rounds):  # the cases interleaved: a change in the machine's load hits all of them
            for name, case in cases.items():
                times[name] = min(times[name], timeit.timeit(case, number=args.number) / args.number)
        base = times["counts"]
        print(f"| {count} | " + " | ".join(f"{t * 1e6:.2f} us ({t / base:.2f}x)" for t in times.values()) + " |")


if __name__ == "__main__":
    main()
