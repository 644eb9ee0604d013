"""The simulated servo's free response at whole samples, computed from tables (no vectorised
transcendental functions, so replay is exact on every CPU) against the closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mpi_ros.mpi.axes.plant import Plant, PlantState
from mpi_ros.mpi.base.params import PlantConfig

RATE = 2000.0


def closed_form(plant: Plant, state: PlantState, forced, t: float) -> tuple[float, float]:
    """y, y' of the loop at time t straight from the formulas, in scalar math."""
    s = t - state.t
    e0 = state.y - forced.y[0]
    e1 = state.dy - forced.dy[0]
    h0, h1 = plant._homogeneous_at(e0, e1, s)
    y = sum(c * s**i for i, c in enumerate(forced.y))
    dy = sum(c * s**i for i, c in enumerate(forced.dy))
    return y + h0, dy + h1


@pytest.mark.parametrize("damping", [0.3, 1.0, 2.5])  # under-, critically and over-damped
def test_tabulated_response_equals_the_closed_form_far_beyond_the_table(damping):
    plant = Plant(PlantConfig(bandwidth_hz=0.5, damping=damping))  # slow: still ringing after 30 s
    state = PlantState(t=1.23456e-3, y=5.0, dy=-40.0)  # an anchor between two samples
    forced = plant.prepare([100.0, 20.0])  # a ramp command
    samples = np.array([3, 4, 5, 4099, 4100, 9000, 60001], dtype=np.int64)
    y, dy = plant.response(state, forced, samples, RATE)
    for k, yk, dyk in zip(samples, y, dy, strict=True):
        want_y, want_dy = closed_form(plant, state, forced, k / RATE)
        assert yk == pytest.approx(want_y, rel=1e-9, abs=1e-9)
        assert dyk == pytest.approx(want_dy, rel=1e-9, abs=1e-9)


def test_response_at_a_sample_does_not_depend_on_the_other_samples_asked():
    plant = Plant(PlantConfig())
    state = PlantState(t=0.0103, y=0.0, dy=300.0)
    forced = plant.prepare([10.0, 500.0, 7.0])
    all_at_once, _ = plant.response(state, forced, np.arange(21, 9000, dtype=np.int64), RATE)
    one = [plant.response(state, forced, np.array([k], dtype=np.int64), RATE)[0][0] for k in (21, 4200, 8999)]
    assert one == [all_at_once[0], all_at_once[4200 - 21], all_at_once[-1]]


def test_coasting_decays_like_the_exponential():
    plant = Plant(PlantConfig(coast_time_constant=0.5))
    state = PlantState(t=2.00031, y=1.0, dy=100.0)
    samples = np.array([4001, 4002, 9000, 20000], dtype=np.int64)
    y, dy = plant.coast(state, samples, RATE)
    for k, yk, dyk in zip(samples, y, dy, strict=True):
        decay = math.exp(-(k / RATE - state.t) / 0.5)
        assert dyk == pytest.approx(100.0 * decay, rel=1e-12)
        assert yk == pytest.approx(1.0 + 100.0 * 0.5 * (1.0 - decay), rel=1e-12)


@pytest.mark.parametrize("config", [PlantConfig(), PlantConfig(bandwidth_hz=0.5, damping=0.3)])  # underflows, rings on
def test_a_window_of_the_free_response_is_what_at_gives_bit_for_bit(config):
    """Windows read the table, the long table (block products tabulated once) or block
    products per window, by where they start: each element is what ``at`` gives."""
    table = Plant(config).table(RATE)
    for starts in ([0, 4000], [4090, 100], [5000, 12000], [12280, 8], [32760, 40000], [70000, 3]):
        m0 = np.array(starts, dtype=np.int64)
        p, q = table.window(m0, 20)
        for row, start in enumerate(starts):
            want_p, want_q = table.at(np.arange(start, start + 20, dtype=np.int64))
            assert p[row].tobytes() == want_p.tobytes()
            assert q[row].tobytes() == want_q.tobytes()
