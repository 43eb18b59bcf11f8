"""The read log (shockcal.study.read_log): a slice records what its holder reads, through every way code reads a dict."""

from __future__ import annotations

import copy
import json

import pytest

from shockcal.study import read_log
from shockcal.study.read_log import RecordingDict, leaf_paths
from shockcal.study.stages import config_slice

SLICE = {"hydro": {"cfl": 0.5, "cells": 4}, "shots": {"S1": {}, "S2": {}}, "inputs": {"A": {"min": 0, "max": 1}}}


def reads(use) -> set[str]:
    seen: set[str] = set()
    use(RecordingDict(copy.deepcopy(SLICE), seen))
    return seen


@pytest.mark.parametrize(("use", "expected"), [
    (lambda c: c["hydro"]["cfl"], {"hydro.cfl"}),
    (lambda c: c["hydro"].get("cells"), {"hydro.cells"}),
    (lambda c: c["hydro"].get("absent", 1), set()),
    (lambda c: dict(**c["hydro"]), {"hydro.cfl", "hydro.cells"}),
    (lambda c: {**c["inputs"]["A"]}, {"inputs.A.min", "inputs.A.max"}),
    (lambda c: [box["max"] for box in c["inputs"].values()], {"inputs.A.max"}),
    (lambda c: copy.deepcopy(c["hydro"]), {"hydro.cfl", "hydro.cells"}),
    (lambda c: json.dumps(c["inputs"]), {"inputs.A.min", "inputs.A.max"}),
    (lambda c: sorted(c["shots"]), {"shots.S1", "shots.S2"}),          # the names a `{names}` path declares
    (lambda c: "S1" in c["shots"], {"shots.S1"}),
    (lambda c: isinstance(c["hydro"], dict) and "cfl" in c["hydro"], set()),   # a presence check reads no value
])
def test_a_slice_records_the_leaves_its_holder_reads(use, expected):
    assert reads(use) == expected


def test_a_change_to_a_section_stays_in_the_slice():
    """A command may override a setting in its slice: the wrapped section is the slice's own, not a copy."""
    sliced = RecordingDict(copy.deepcopy(SLICE), set())
    sliced["hydro"]["cfl"] = 0.25
    assert sliced["hydro"]["cfl"] == 0.25


def test_the_declared_leaves_are_every_leaf_and_every_name():
    assert leaf_paths(SLICE) == {"hydro.cfl", "hydro.cells", "shots.S1", "shots.S2", "inputs.A.min", "inputs.A.max"}


def test_names_slice_the_keys_alone_and_a_full_path_keeps_its_values():
    config = {"shots": {"S1": {"flyer_mm": 4.0, "analysis": {"window_after_arrival_us": 1.1}}, "S2": {"flyer_mm": 3.9}}}
    assert config_slice(config, ["shots.{names}"]) == {"shots": {"S1": {}, "S2": {}}}
    both = {"shots": {"S1": {"analysis": {"window_after_arrival_us": 1.1}}, "S2": {}}}
    assert config_slice(config, ["shots.{names}", "shots.S1.analysis"]) == both
    assert config_slice(config, ["shots.S1.analysis", "shots.{names}"]) == both


def test_without_the_variable_the_slice_is_the_plain_dict(monkeypatch, tmp_path):
    monkeypatch.delenv(read_log.READ_LOG, raising=False)
    sliced = {"hydro": {"cfl": 0.5}}
    assert read_log.recorded(sliced, "simulate") is sliced
    monkeypatch.setenv(read_log.READ_LOG, str(tmp_path))
    monkeypatch.setattr(read_log.atexit, "register", lambda write, *args: write(*args))   # write at once
    wrapped = read_log.recorded(sliced, "simulate")
    assert isinstance(wrapped, RecordingDict) and wrapped == sliced
    (written,) = tmp_path.glob("*-simulate.json")
    assert json.loads(written.read_text()) == {"stage": "simulate", "declared": ["hydro.cfl"], "reads": []}
