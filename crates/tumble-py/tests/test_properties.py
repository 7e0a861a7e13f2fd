"""Property test of the bulk setters' atomicity (issue 14): random worlds, random mixes of
good and bad rows, arrays of wrong shapes and dtypes. Every call either succeeds, and the
state is then what was set, or raises ValueError/TypeError and leaves the state hash as it
was. A call given a row that can only be refused must raise.

The budget is small (100 examples) so that the suite stays fast; for a long search run
``TUMBLE_HYPOTHESIS_EXAMPLES=20000 target/venv/bin/python -m pytest
crates/tumble-py/tests/test_properties.py``.
"""

import os

import numpy as np

from hypothesis import given, settings, strategies as st

import tumble

EXAMPLES = int(os.environ.get("TUMBLE_HYPOTHESIS_EXAMPLES", "100"))
WIDTH = {"positions": 3, "orientations": 4, "velocities": 3, "angular_velocities": 3}

# Values a row may hold, and whether each is surely refused in that array. 1e308 is a
# valid orientation component ([1e308, 0, 0, 1e308] is a rotation), so no verdict there.
GOOD = {
    "positions": st.floats(-1e3, 1e3),
    "orientations": st.floats(-1.0, 1.0),
    "velocities": st.floats(-1e2, 1e2),
    "angular_velocities": st.floats(-1e2, 1e2),
}
BAD = [np.nan, np.inf, -np.inf]
HUGE = [1e308, -1e308, 1e12]


@st.composite
def worlds(draw):
    """A world of 0 to 5 dynamic spheres (their centre of mass is their frame's origin and
    their inertia isotropic, so what was set reads back exactly), stepped a little."""
    n = draw(st.integers(0, 5))
    world = tumble.World(gravity=(0, -9.8, 0))
    for i in range(n):
        world.add_body(tumble.Sphere(0.1 + 0.1 * draw(st.integers(0, 3))), mass=1.0,
                       position=(3.0 * i, 0, 0), velocity=(0, draw(st.floats(-5, 5)), 0))
    world.step(0.01, steps=draw(st.integers(0, 3)))
    return world


@st.composite
def array_for(draw, field, n):
    """An array for `field` of `n` bodies, and whether the engine must refuse it."""
    width = WIDTH[field]
    kind = draw(st.sampled_from(["good", "good", "bad_rows", "shape", "dtype", "list"]))
    rows = np.array(draw(st.lists(st.lists(GOOD[field], min_size=width, max_size=width),
                                  min_size=n, max_size=n)), dtype=float).reshape(n, width)
    if field == "orientations":
        # Good quaternions are far from zero.
        rows[:, 3] = np.where(np.abs(rows).max(axis=1) < 0.5, 1.0, rows[:, 3])
    if kind in ("good", "list"):
        return (rows.tolist() if kind == "list" else rows), False
    if kind == "shape":
        shape = draw(st.sampled_from([(n + 1, width), (n, width - 1), (n * width,), (1, n, width)]))
        return np.zeros(shape), True
    if kind == "dtype":
        dtype = draw(st.sampled_from([complex, str, object]))
        return rows.astype(dtype), True
    if n == 0:
        return rows, False
    i = draw(st.integers(0, n - 1))
    j = draw(st.integers(0, width - 1))
    surely = True
    value = draw(st.sampled_from(BAD + HUGE + ["zero"]))
    if value == "zero":
        if field == "orientations":
            rows[i] = 0.0
        else:
            rows[i, j] = 0.0
            surely = False  # zero is a good position or velocity
    else:
        rows[i, j] = value
        if field == "orientations" and value in HUGE:
            surely = False
    return rows, surely


def expected_orientations(q):
    q = np.asarray(q, dtype=float)
    q = q / np.abs(q).max(axis=1, keepdims=True)
    return q / np.linalg.norm(q, axis=1, keepdims=True)


@st.composite
def edits(draw):
    world = draw(worlds())
    n = len(world)
    fields = draw(st.lists(st.sampled_from(list(WIDTH)), min_size=1, max_size=4, unique=True))
    arrays, surely = {}, False
    for f in fields:
        arrays[f], bad = draw(array_for(f, n))
        surely |= bad
    return world, arrays, surely


# No example database: the suite leaves no .hypothesis directory behind; a failure prints
# the example (and a @reproduce_failure line) to replay it.
@settings(max_examples=EXAMPLES, deadline=None, database=None)
@given(edits())
def test_bulk_setters_are_all_or_nothing(edit):
    world, arrays, surely_refused = edit
    before = world.state_hash()
    try:
        if len(arrays) == 1:
            [(field, value)] = arrays.items()
            setattr(world, field, value)
        else:
            world.set_state(**arrays)
    except (ValueError, TypeError):
        assert world.state_hash() == before, f"a refused set changed the world: {arrays}"
        return
    assert not surely_refused, f"accepted {arrays}"
    tol = 1e-5 if tumble.SINGLE_PRECISION else 1e-12
    for field, value in arrays.items():
        got = getattr(world, field)
        want = expected_orientations(value) if field == "orientations" else np.asarray(value, dtype=float)
        np.testing.assert_allclose(got, want.reshape(got.shape), rtol=tol, atol=tol)
