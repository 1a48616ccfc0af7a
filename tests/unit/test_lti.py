"""Unit tests for siloflow.analysis.numerics.lti (convolution with the RTD, VRR, recirculation) on exact cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.analysis.numerics.lti import (
    Recirculation,
    VRRTable,
    carson_royal_recycle,
    coefficient_of_variation,
    convolve_with_rtd,
    recirculate,
    recirculations_to_homogenise,
    sine_input,
    square_input,
    variance_reduction_ratio,
    vrr_versus_period,
)
from siloflow.analysis.numerics.rtd import johanson_rtd, perfect_mixer_rtd, plug_flow_rtd

TAU = 1.0
DT = 2.0e-3
MEMORY = 25.0  # RTD tabulated over 25 tau: exp(-25) ~ 1e-11 is cut off


def mixer_table(tau: float = TAU, dt: float = DT, span: float = MEMORY):
    t = np.arange(int(round(span * tau / dt)) + 1) * dt
    return t, perfect_mixer_rtd(t, tau)


# --------------------------------------------------------------------------- convolution


@pytest.mark.parametrize("method", ["direct", "fft", "auto"])
def test_unit_impulse_returns_the_rtd(method):
    dt = 2.0**-7
    t = np.arange(300) * dt
    e = perfect_mixer_rtd(t[:200], 0.3)  # shorter than the signal: zero beyond
    impulse = np.zeros(300)
    impulse[0] = 1.0 / dt
    out = convolve_with_rtd(t, impulse, e, method=method)
    expected = np.concatenate([e, np.zeros(100)])
    if method == "fft":
        np.testing.assert_allclose(out, expected, rtol=0, atol=1e-14 * e.max())
    else:
        np.testing.assert_array_equal(out, expected)  # dt a power of 2: bit for bit


def test_unit_impulse_with_any_step_and_a_longer_rtd():
    dt = 0.013
    t = 5.0 + np.arange(100) * dt
    e = perfect_mixer_rtd(np.arange(250) * dt, 0.4)  # longer than the signal: the tail is never reached
    impulse = np.zeros(100)
    impulse[0] = 1.0 / dt
    np.testing.assert_allclose(convolve_with_rtd(t, impulse, e), e[:100], rtol=1e-15, atol=0)


def test_delayed_impulse_and_causality():
    dt = 0.5
    t = np.arange(20) * dt
    e = np.arange(6, dtype=float)
    c = np.zeros(20)
    c[4] = 1.0 / dt
    out = convolve_with_rtd(t, c, e)
    np.testing.assert_array_equal(out[:4], 0.0)
    np.testing.assert_array_equal(out[4:10], e)
    changed = c.copy()
    changed[12:] = 7.0
    np.testing.assert_array_equal(convolve_with_rtd(t, changed, e)[:12], out[:12])


def test_constant_input_with_matching_history_stays_constant():
    t, e = mixer_table(span=10.0)
    e = e / (np.sum(e) * DT)
    c = np.full(t.size, 0.37)
    out = convolve_with_rtd(t, c, e, c_before=0.37)
    np.testing.assert_allclose(out, 0.37, rtol=1e-12)
    # without the history the output rises as 0.37 * F(t)
    rising = convolve_with_rtd(t, c, e)
    np.testing.assert_allclose(rising, 0.37 * np.cumsum(e) * DT, rtol=1e-12)


def test_direct_and_fft_agree():
    rng = np.random.default_rng(3)
    t = np.arange(3000) * 0.01
    c = rng.uniform(size=3000)
    e = perfect_mixer_rtd(np.arange(2500) * 0.01, 2.0)
    direct = convolve_with_rtd(t, c, e, method="direct")
    fft = convolve_with_rtd(t, c, e, method="fft")
    np.testing.assert_allclose(fft, direct, rtol=0, atol=1e-12 * np.abs(direct).max())


@pytest.mark.parametrize(
    "args, kwargs, match",
    [
        (([0.0, 1.0, 3.0], [1.0, 1.0, 1.0], [1.0]), {}, "time"),
        (([0.0], [1.0], [1.0]), {}, "time"),
        (([0.0, 1.0], [1.0], [1.0]), {}, "c_in"),
        (([0.0, 1.0], [1.0, np.nan], [1.0]), {}, "c_in"),
        (([0.0, 1.0], [1.0, 1.0], []), {}, "E"),
        (([0.0, 1.0], [1.0, 1.0], [1.0]), {"method": "slow"}, "method"),
        (([0.0, 1.0], [1.0, 1.0], [1.0]), {"c_before": math.inf}, "c_before"),
    ],
)
def test_convolve_rejects_bad_input(args, kwargs, match):
    with pytest.raises(ValueError, match=match):
        convolve_with_rtd(*args, **kwargs)


# --------------------------------------------------------------------------- continuous mode


def test_inputs():
    t = np.arange(8) * 0.25
    np.testing.assert_allclose(sine_input(t, 0.5, 0.2, 1.0), 0.5 + 0.2 * np.sin(2 * np.pi * t), rtol=1e-15)
    np.testing.assert_array_equal(square_input(t, 0.5, 0.5, 1.0), [1, 1, 0, 0, 1, 1, 0, 0])
    np.testing.assert_array_equal(square_input(t, 0.0, 1.0, 1.0, duty=0.25), [1, -1, -1, -1, 1, -1, -1, -1])
    # whole periods: variance amplitude^2 / 2 (sine) and amplitude^2 (square)
    fine = np.arange(4000) * 1e-3
    assert np.var(sine_input(fine, 0.5, 0.3, 0.5)) == pytest.approx(0.045, rel=1e-12)
    assert np.var(square_input(fine, 0.5, 0.3, 0.5)) == pytest.approx(0.09, rel=1e-12)
    # switches exactly on the period even with round-off in t / period
    period = 0.1
    t = np.arange(100) * 0.01
    levels = square_input(t, 0.0, 1.0, period)
    np.testing.assert_array_equal(levels, np.tile([1.0] * 5 + [-1.0] * 5, 10))
    with pytest.raises(ValueError, match="period"):
        sine_input(t, 0.0, 1.0, 0.0)
    with pytest.raises(ValueError, match="amplitude"):
        square_input(t, 0.0, -1.0, 1.0)
    with pytest.raises(ValueError, match="duty"):
        square_input(t, 0.0, 1.0, 1.0, duty=1.0)


@pytest.mark.parametrize("period_over_tau", [0.5, 1.0, 2.0, 5.0])
def test_perfect_mixer_vrr_is_one_plus_omega_tau_squared(period_over_tau):
    t_e, e = mixer_table()
    e = e / (np.sum(e) * DT)
    period = period_over_tau * TAU
    memory = e.size - 1
    steady = int(round(4 * period / DT))  # four whole periods
    t = np.arange(memory + steady) * DT
    c_in = sine_input(t, 0.5, 0.5, period)
    c_out = convolve_with_rtd(t, c_in, e)
    omega = 2.0 * np.pi / period
    expected = 1.0 + (omega * TAU) ** 2
    assert variance_reduction_ratio(c_in, c_out, steady_from=memory) == pytest.approx(expected, rel=0.01)
    # the same window given as a time
    assert variance_reduction_ratio(c_in, c_out, steady_from=t[memory] - DT / 2, time=t) == pytest.approx(
        expected, rel=0.01
    )


def test_vrr_versus_period_perfect_mixer_and_plug_flow():
    t_e, e = mixer_table()
    fractions = np.array([0.25, 0.5, 1.0, 2.0, 5.0])
    table = vrr_versus_period(e, t_e, fractions, n_periods=4)
    assert isinstance(table, VRRTable)
    assert table.t_mean == pytest.approx(TAU, rel=1e-5)
    omega = 2.0 * np.pi / table.period
    np.testing.assert_allclose(table.vrr, 1.0 + (omega * TAU) ** 2, rtol=0.01)
    assert np.all(np.diff(table.vrr) < 0)  # slower inputs are blended less
    rows = table.rows()
    assert len(rows) == 5 and rows[0]["period_over_tm"] == 0.25 and rows[0]["waveform"] == "sine"

    plug = plug_flow_rtd(t_e, tau=2.0)  # narrow pulse: no blending
    table = vrr_versus_period(plug, t_e, [0.25, 0.5, 1.0, 2.0], n_periods=4)
    assert table.t_mean == pytest.approx(2.0, rel=1e-9)
    np.testing.assert_allclose(table.vrr, 1.0, rtol=0.01)


def test_square_wave_vrr_of_a_perfect_mixer():
    t_e, e = mixer_table(dt=5e-3)
    table = vrr_versus_period(e, t_e, [0.5, 1.0, 4.0], waveform="square", n_periods=4, t_mean=TAU)
    assert table.waveform == "square" and table.t_mean == TAU
    assert np.all(table.vrr > 1.0) and np.all(np.diff(table.vrr) < 0)
    # square wave of period P through 1 / (1 + i w tau): harmonics k = 1, 3, 5, ... with weights 8 / (pi k)^2
    k = np.arange(1, 20001, 2)
    for period, vrr in zip(table.period, table.vrr):
        omega = 2 * np.pi * k / period
        ratio = np.sum(8 / (np.pi * k) ** 2 / (1 + (omega * TAU) ** 2))
        assert vrr == pytest.approx(1.0 / ratio, rel=0.02)


def test_vrr_versus_period_rejects_bad_input():
    t_e, e = mixer_table(dt=0.01, span=5.0)
    with pytest.raises(ValueError, match="periods_over_tm"):
        vrr_versus_period(e, t_e, [0.0])
    with pytest.raises(ValueError, match="periods_over_tm"):
        vrr_versus_period(e, t_e, [0.01])  # one sample per period
    with pytest.raises(ValueError, match="waveform"):
        vrr_versus_period(e, t_e, [1.0], waveform="triangle")
    with pytest.raises(ValueError, match="time"):
        vrr_versus_period(e, t_e + 1.0, [1.0])
    with pytest.raises(ValueError, match="n_periods"):
        vrr_versus_period(e, t_e, [1.0], n_periods=0)


def test_variance_reduction_ratio_and_coefficient_of_variation_by_hand():
    c_in = np.array([5.0, 0.0, 2.0, 0.0, 2.0])
    c_out = np.array([9.0, 1.0, 1.5, 1.0, 1.5])
    # window from index 1: var([0, 2, 0, 2]) = 1, var([1, 1.5, 1, 1.5]) = 0.0625
    assert variance_reduction_ratio(c_in, c_out, steady_from=1) == pytest.approx(16.0, rel=1e-15)
    assert variance_reduction_ratio(c_in, np.ones(5), steady_from=1) == math.inf
    assert coefficient_of_variation([1.0, 3.0]) == pytest.approx(0.5, rel=1e-15)
    with pytest.raises(ValueError, match="c_in"):
        variance_reduction_ratio(np.ones(5), c_out)
    with pytest.raises(ValueError, match="steady_from"):
        variance_reduction_ratio(c_in, c_out, steady_from=4)
    with pytest.raises(ValueError, match="steady_from"):
        variance_reduction_ratio(c_in, c_out, steady_from=-1)
    with pytest.raises(ValueError, match="c_out"):
        variance_reduction_ratio(c_in, c_out[:3])
    with pytest.raises(ValueError, match="c"):
        coefficient_of_variation([-1.0, 1.0])


# --------------------------------------------------------------------------- discontinuous mode


def layered_batch(n: int, blue_fraction: float, layers: int = 1) -> np.ndarray:
    """Inlet concentration of a batch of n samples: `layers` blue layers alternating with white ones."""
    c = np.zeros(n)
    per_layer = n // layers
    blue = int(round(blue_fraction * per_layer))
    for layer in range(layers):
        c[layer * per_layer : layer * per_layer + blue] = 1.0
    return c


@pytest.mark.parametrize("method", ["direct", "fft"])
def test_recirculation_conserves_tracer_mass_per_pass(method):
    dt = 5e-3
    t_e, e = mixer_table(dt=dt, span=15.0)
    n = int(round(TAU / dt))  # one residence time of inlet
    t = np.arange(n) * dt
    c_first = layered_batch(n, 0.25, layers=3)
    result = recirculate(c_first, e, t, passes=5, method=method)
    assert isinstance(result, Recirculation)
    assert result.input_mass == pytest.approx(np.sum(c_first) * dt, rel=1e-15)
    np.testing.assert_allclose(result.pass_mass, result.input_mass, rtol=1e-9)
    for p, (axis, values) in enumerate(zip(result.pass_time, result.pass_concentration), start=1):
        assert values.size == n + p * (e.size - 1) == axis.size
        np.testing.assert_allclose(axis, t[0] + np.arange(axis.size) * dt, rtol=1e-15)
        assert float(np.sum(values) * dt) == pytest.approx(result.input_mass, rel=1e-9)
    # pass n + 1 has the output of pass n as input
    e_norm = e / (np.sum(e) * dt)
    second = convolve_with_rtd(result.pass_time[1], np.pad(result.pass_concentration[0], (0, e.size - 1)), e_norm,
                               method=method)
    np.testing.assert_allclose(second, result.pass_concentration[1], rtol=0, atol=1e-12)
    total = np.zeros(result.time.size)
    for values in result.pass_concentration:
        total[: values.size] += values
    np.testing.assert_allclose(result.concentration, total, rtol=1e-15)
    assert result.next_pass.shape == result.time.shape


def test_recirculation_of_plug_flow_repeats_the_batch_and_never_homogenises():
    dt = 0.125
    lag = 8  # plug flow: residence time 8 dt = one batch length
    e = np.zeros(lag + 1)
    e[lag] = 1.0 / dt
    c_first = layered_batch(lag, 0.5)  # 4 blue samples, 4 white
    t = np.arange(lag) * dt
    result = recirculate(c_first, e, t, passes=4)
    for p, values in enumerate(result.pass_concentration, start=1):
        expected = np.zeros(values.size)
        expected[p * lag : (p + 1) * lag] = c_first
        np.testing.assert_array_equal(values, expected)
    np.testing.assert_array_equal(result.concentration[lag : 5 * lag], np.tile(c_first, 4))
    assert math.isnan(recirculations_to_homogenise(result.concentration[lag : 5 * lag], 0.5, per_pass_length=lag))


def test_recirculation_of_a_perfect_mixer_is_homogeneous_once_the_batch_is_in():
    dt = 5e-3
    t_e, e = mixer_table(dt=dt, span=15.0)
    n = int(round(TAU / dt))
    c_first = layered_batch(n, 0.13)
    result = recirculate(c_first, e, np.arange(n) * dt, passes=25)
    # up to 8 t_m the 26th pass (the first one left out) contributes nothing
    window = result.concentration[: 8 * n]
    assert np.max(result.next_pass[: 8 * n]) < 1e-5
    # the renewal density of an exponential RTD is constant (1 / tau): from t_m on the outlet carries
    # the batch's blue fraction, 13 % (to the first-order discretisation error)
    np.testing.assert_allclose(window[n:], 0.13, rtol=5e-3)
    assert recirculations_to_homogenise(window, 0.13, 0.10, per_pass_length=n) < 1.0


def test_recirculation_of_a_triangular_rtd_homogenises_in_a_few_passes():
    dt = 5e-3
    t_e = np.arange(int(round(4.0 / dt)) + 1) * dt
    e = johanson_rtd(t_e, TAU, 0.5, 1.0)  # narrow, symmetric: close to mass flow
    n = int(round(TAU / dt))
    c_first = layered_batch(n, 0.13)
    result = recirculate(c_first, e, np.arange(n) * dt, passes=40)
    window = result.concentration[: 20 * n]
    assert np.max(result.next_pass[: 20 * n]) < 1e-12
    assert window[-1] == pytest.approx(0.13, rel=1e-6)
    recirculations = recirculations_to_homogenise(window, 0.13, 0.10, per_pass_length=n)
    assert 2.0 < recirculations < 5.0
    # a wider band is reached sooner
    assert recirculations_to_homogenise(window, 0.13, 0.30, per_pass_length=n) < recirculations


def test_recirculations_to_homogenise_by_hand():
    c = np.array([0.0, 2.0, 0.5, 1.05, 0.95, 1.0])
    assert recirculations_to_homogenise(c, 1.0, 0.10, per_pass_length=2) == 1.5
    assert recirculations_to_homogenise(c, 1.0, 0.10) == 3.0
    assert recirculations_to_homogenise(c[3:], 1.0) == 0.0
    assert math.isnan(recirculations_to_homogenise(np.array([1.0, 1.0, 2.0]), 1.0))
    assert recirculations_to_homogenise(np.array([0.0, 1.0, 1.0]), None, 0.6) == 1.0  # mean 2/3
    with pytest.raises(ValueError, match="mean"):
        recirculations_to_homogenise(c, 0.0)
    with pytest.raises(ValueError, match="tolerance"):
        recirculations_to_homogenise(c, 1.0, 0.0)
    with pytest.raises(ValueError, match="per_pass_length"):
        recirculations_to_homogenise(c, 1.0, 0.1, per_pass_length=0)


def test_recirculate_rejects_bad_input():
    t = np.arange(4) * 0.1
    with pytest.raises(ValueError, match="passes"):
        recirculate(np.ones(4), np.ones(3), t, passes=0)
    with pytest.raises(ValueError, match="c_first_input"):
        recirculate(np.ones(3), np.ones(3), t, passes=1)
    with pytest.raises(ValueError, match="E"):
        recirculate(np.ones(4), np.zeros(3), t, passes=1)


def test_carson_royal_delay_passes_shift_exactly():
    dt = 0.125
    t = np.arange(40) * dt
    delay = np.zeros(40)
    delay[3] = 1.0 / dt  # plug flow of 3 dt
    rows = carson_royal_recycle(delay, t, passes=4)
    assert rows.shape == (4, 40)
    for n in range(4):
        expected = np.zeros(40)
        expected[3 * (n + 1)] = 1.0 / dt
        np.testing.assert_array_equal(rows[n], expected)


def test_carson_royal_perfect_mixer_gives_erlang_curves():
    tau = 1.0
    dt = 1e-3
    t = np.arange(0, 40001) * dt
    e1 = perfect_mixer_rtd(t, tau)
    rows = carson_royal_recycle(e1, t, passes=4)
    area = float(np.sum(e1) * dt)
    for n in range(1, 5):
        # the rectangle rule (first order) shifts the n-th pass by (n - 1) dt and scales by O(dt)
        shifted = t + (n - 1) * dt
        erlang = shifted ** (n - 1) * np.exp(-shifted / tau) / (tau**n * math.factorial(n - 1))
        np.testing.assert_allclose(rows[n - 1], erlang, atol=2.5e-3 * erlang.max())
        # discrete convolution multiplies the areas; the axis holds the whole curve
        assert float(np.sum(rows[n - 1]) * dt) == pytest.approx(area**n, rel=1e-9)
    total = rows.sum(axis=0)
    assert total[-1] < 1e-9


def test_carson_royal_rejects_bad_input():
    t = np.arange(5) * 0.1
    with pytest.raises(ValueError, match="passes"):
        carson_royal_recycle(np.ones(5), t, 0)
    with pytest.raises(ValueError, match="time"):
        carson_royal_recycle(np.ones(5), t + 0.05, 2)
    with pytest.raises(ValueError, match="first_pass_E"):
        carson_royal_recycle(np.ones(4), t, 2)
    with pytest.raises(ValueError, match="time"):
        carson_royal_recycle(np.ones(5), [0.0, 0.1, 0.3, 0.4, 0.5], 2)
