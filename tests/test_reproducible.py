"""Numbers across machines: the hip motor's solves use no per-CPU kernel, records name their machine, and a record
is compared with a walk today to the last digit on its machine and within a stated tolerance elsewhere."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from drake_biped.hip_motor import DYN_F, DYN_J, DYN_M, DYN_N, DYN_SIZE, constrained_inverse_k
from drake_biped.versions import CROSS_MACHINE_RTOL, MACHINE_IDENTITY, compare_with_record, machine, versions


def _dynamics(rng: np.random.Generator, rows: int) -> np.ndarray:
    a = rng.normal(size=(9, 9))
    dyn = np.zeros(DYN_SIZE)
    dyn[DYN_M : DYN_M + 81] = (a @ a.T + 0.5 * np.eye(9)).ravel()
    dyn[DYN_J : DYN_J + 9 * rows] = rng.normal(size=(rows, 9)).ravel()
    dyn[DYN_N] = rows
    dyn[DYN_F : DYN_F + 9] = rng.normal(size=9)
    return dyn


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), rows=st.integers(1, 5))
def test_the_motors_constrained_inverse_is_the_formula_and_holds_the_constraints(seed, rows):
    dyn = _dynamics(np.random.default_rng(seed), rows)
    p, b = constrained_inverse_k(dyn)
    m = dyn[DYN_M : DYN_M + 81].reshape(9, 9)
    jc = dyn[DYN_J : DYN_J + 9 * rows].reshape(rows, 9)
    mi = np.linalg.inv(m)
    expected = mi - mi @ jc.T @ np.linalg.solve(jc @ mi @ jc.T, jc @ mi)
    scale = np.abs(expected).max()
    assert np.abs(p - expected).max() <= 1e-8 * scale
    assert np.abs(jc @ p).max() <= 1e-8 * scale  # no acceleration along a held constraint
    assert np.allclose(b, p @ dyn[DYN_F : DYN_F + 9], rtol=1e-9, atol=1e-9 * scale)


def test_the_compiled_solve_rounds_as_its_python_loops_to_the_last_bit():
    """The compiled kernel gives the digits of the same loops run by the Python interpreter (IEEE doubles, no
    fused multiply-add, no reordered sum): no BLAS or LAPACK kernel chosen per CPU, and no fast-math, enters it.
    numpy's np.linalg.inv here differs from both in the last digits."""
    rng = np.random.default_rng(7)
    for rows in (3, 4, 5):
        dyn = _dynamics(rng, rows)
        compiled = constrained_inverse_k(dyn)
        interpreted = constrained_inverse_k.py_func(dyn)
        for a, b in zip(compiled, interpreted):
            assert np.array_equal(a, b)


def test_records_name_the_machine_they_were_made_on():
    record = versions()
    assert record["machine"] is machine()
    for key in MACHINE_IDENTITY:
        assert key in machine()
    assert machine()["cpu"] and machine()["architecture"] and machine()["python"].count(".") == 2
    assert machine()["numpy"] == np.__version__


def test_a_record_of_this_machine_is_compared_to_the_last_digit():
    here = versions()
    same = compare_with_record(0.2192145760134881, 0.2192145760134881, here)
    assert same.exact and same.agrees and "last digit" in same.text
    off = compare_with_record(0.2192145760134881, 0.2192145760134882, here)
    assert off.exact and not off.agrees and "DIFFERS" in off.text


def test_another_machines_record_is_compared_within_the_stated_tolerance():
    other = {**versions(), "machine": {**machine(), "cpu": "another CPU"}}
    near = compare_with_record(0.21921457601348812, 0.21930521161985025, other)
    assert not near.exact and near.agrees and near.rtol == CROSS_MACHINE_RTOL
    assert f"within a relative {CROSS_MACHINE_RTOL:g}" in near.text and "another machine" in near.text
    far = compare_with_record(0.2192, 0.2192 * (1 + 2 * CROSS_MACHINE_RTOL), other)
    assert not far.agrees and "DIFFERS" in far.text
    # a record made before machines were recorded, or a kernel-only difference of the OS's name
    old = compare_with_record(0.2192, 0.2192 * (1 + 0.5 * CROSS_MACHINE_RTOL), {"drake": "1.51.1"})
    assert old.agrees and not old.exact and "names no machine" in old.text
    renamed = {**versions(), "machine": {**machine(), "os": "Linux-another-kernel"}}
    assert compare_with_record(1.0, 1.0, renamed).exact


@pytest.mark.parametrize("today", [math.nan, math.inf])
def test_a_walk_that_gives_no_number_never_agrees(today):
    assert not compare_with_record(0.2192, today, {}).agrees


def test_walk_of_a_record_says_how_its_number_compares(tmp_path, capsys):
    """`walk --params RESULT.json` walks the record's configuration and says how its C_mt compares with the
    record's, and by which rule: the last digit on this machine, the tolerance on another."""
    import json

    from drake_biped.cli import main

    assert main(["walk", "--params", "fast_servo", "--distance", "0.5", "--no-animation", "--out",
                 str(tmp_path / "a")]) == 0
    record_path = tmp_path / "a" / "result.json"
    capsys.readouterr()
    assert main(["walk", "--params", str(record_path), "--no-animation", "--out", str(tmp_path / "b")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("gait: fast_servo (sha256 ")  # the record's walker, named by what it walks
    assert json.loads((tmp_path / "b" / "result.json").read_text())["gait"]["name"] == "fast_servo"
    line = [x for x in out if x.startswith("record ")]
    assert len(line) == 1 and "equal to the last digit (the record's machine: compared to the last digit)" in line[0]
    record = json.loads(record_path.read_text())
    record["versions"]["machine"]["cpu"] = "another CPU"
    record["cost_of_transport"] *= 1 + 0.5 * CROSS_MACHINE_RTOL
    record_path.write_text(json.dumps(record))
    assert main(["walk", "--params", str(record_path), "--no-animation", "--out", str(tmp_path / "c")]) == 0
    line = [x for x in capsys.readouterr().out.splitlines() if x.startswith("record ")]
    assert "agrees" in line[0] and "another machine than the record" in line[0]
