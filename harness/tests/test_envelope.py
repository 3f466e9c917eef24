"""harness/envelope.py on synthetic sequences whose truth is known: a smooth power law (its
midpoints lie on it), an order-1 error with an erratic coefficient (the phase of an event within
its step, as a spring-dashpot collision's end), too few points, and noise that does not shrink."""
import math

import numpy as np

from harness import envelope as E
from harness.study import analyse

LIMIT = 0.5


def phase_error(h, t_event=0.0409812649):
    """c(h) h: c a sawtooth of the event's phase within its step (period 1 in t_event / h), so the
    coefficient jumps about [-30, +10] from one h to the next, as measured on the restitution."""
    phase = (t_event / h) % 1.0
    return (10 - 40 * phase) * h


def levels(h0, n, factor=0.5):
    return [h0 * factor ** k for k in range(n)]


def test_a_smooth_power_law_lies_on_itself_at_the_midpoints():
    hs = levels(1e-2, 4)
    q = lambda h: LIMIT + 3.0 * h ** 2 + 40 * h ** 3      # noqa: E731 -- a smooth sequence
    qs = [q(h) for h in hs]
    a = analyse(hs, qs, 0.5)
    assert a["verdict"] == "converging"
    mids = E.midpoints(hs, 0.5)
    deps = E.departures(hs, qs, a, mids, [q(h) for h in mids])
    assert E.smooth(deps), deps
    assert max(deps) < 0.05


def test_an_erratic_coefficient_is_caught_at_the_midpoints():
    """Levels chosen so that their four values fall on one side and look like order ~1 (the
    restitution's trap); the midpoints show it is not a power law."""
    hs = levels(2 ** -11, 4)
    qs = [LIMIT + phase_error(h) for h in hs]
    mids = E.midpoints(hs, 0.5)
    qm = [LIMIT + phase_error(h) for h in mids]
    a = analyse(hs, qs, 0.5)
    if a["verdict"] == "converging":
        assert not E.smooth(E.departures(hs, qs, a, mids, qm))
    else:
        assert a["verdict"] in ("asymptotic?", "not converging")


def test_the_envelope_bounds_the_error_and_its_advice_meets_the_truth():
    hs = levels(2 ** -11, 12)
    pts = hs + E.midpoints(hs, 0.5) + E.samples(hs)
    env = E.bound(pts, [LIMIT + phase_error(h) for h in pts])
    assert env["ok"], env["text"]
    assert abs(env["order"] - 1) < 0.2
    assert abs(env["limit"] - LIMIT) <= env["uncertainty"]
    worst = 30.0      # the sawtooth's largest |c|
    for target in (1e-2, 1e-3, 1e-4):
        h, predicted = E.advise(env, target)
        assert h is not None, predicted
        # every step up to h meets the target against the TRUE limit (the sawtooth's worst phase)
        assert worst * h / LIMIT <= target
        # and h is not needlessly small: within 4 of the largest step whose worst phase meets it
        assert h >= target * LIMIT / worst / 4


def test_a_midpoint_without_a_value_is_no_evidence():
    assert E.smooth([0.01, None, 0.02])
    assert not E.smooth([0.01, None, 0.9])


def test_too_few_points_give_no_envelope_and_say_what_to_add():
    hs = levels(2 ** -11, 4)
    pts = hs + E.midpoints(hs, 0.5)
    env = E.bound(pts, [LIMIT + phase_error(h) for h in pts])
    assert not env["ok"]
    assert "--levels 6" in env["text"]
    h, why = E.advise(env, 1e-3)
    assert h is None and "no envelope" in why


def test_an_unresolved_limit_refuses_a_fine_target():
    hs = levels(2 ** -9, 6)
    pts = hs + E.midpoints(hs, 0.5) + E.samples(hs)
    env = E.bound(pts, [LIMIT + phase_error(h) for h in pts])
    assert env["ok"]
    h, why = E.advise(env, 1e-5)
    assert h is None and "add levels" in why


def test_noise_that_does_not_shrink_is_not_bounded():
    rng = np.random.default_rng(7)
    hs = levels(1e-3, 8)
    pts = hs + E.midpoints(hs, 0.5) + E.samples(hs)
    env = E.bound(pts, list(LIMIT + 0.01 * rng.standard_normal(len(pts))))
    assert not env["ok"]
    assert "does not shrink" in env["text"]


def test_samples_lie_inside_the_two_coarsest_intervals_and_miss_the_levels():
    hs = levels(1.0, 6)
    s = E.samples(hs)
    assert len(s) == E.ENVELOPE_SAMPLES
    assert all(hs[2] < h < hs[0] for h in s)
    taken = hs + E.midpoints(hs, 0.5)
    assert all(min(abs(math.log(h / t)) for t in taken) > 1e-3 for h in s)
