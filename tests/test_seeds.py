"""Named random streams: one SeedSequence(study.seed), distinct and stable streams per stage."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from shockcal.design.tables import latin_hypercube
from shockcal.seeds import STREAMS, stream_seed
from shockcal.study.config import prior_bounds


def test_design_stream_is_the_study_seed_itself(paper_config):
    # the training hypercube is the one `study.seed` gave before named streams existed
    seed = paper_config["study"]["seed"]
    assert stream_seed(seed, "design") == seed
    unit = latin_hypercube(prior_bounds(paper_config), 5, stream_seed(seed, "design"))
    assert unit.equals(latin_hypercube(prior_bounds(paper_config), 5, seed))


def test_streams_are_deterministic_and_distinct():
    keyed = [(name, key) for name in STREAMS for key in [(), (0,), (1,), ("104S",), ("104S", "105S", "106S")]]
    for study_seed in (0, 1, 20181128):
        seeds = [stream_seed(study_seed, name, *key) for name, key in keyed]
        assert seeds == [stream_seed(study_seed, name, *key) for name, key in keyed]
        assert len(set(seeds + [study_seed])) == len(seeds) + 1, "two streams share a seed"
        assert all(0 <= s < 2**32 for s in seeds)


def test_streams_of_neighbouring_study_seeds_do_not_overlap():
    # the old offsets (study.seed + 11 for the sampler, + 12, + 13, ...) made seed s's sampler stream
    # the next seed's check stream; named streams of seeds 0..49 never coincide
    seeds = [stream_seed(s, name) for s, name in itertools.product(range(50), STREAMS)]
    assert len(set(seeds)) == len(seeds)


def test_stream_draws_are_independent_of_the_root():
    root = np.random.default_rng(stream_seed(5, "design")).random(1000)
    child = np.random.default_rng(stream_seed(5, "calibration")).random(1000)
    assert abs(np.corrcoef(root, child)[0, 1]) < 0.1


def test_unknown_stream_and_keyed_design_are_errors():
    with pytest.raises(ValueError, match="unknown random stream 'sampler'"):
        stream_seed(0, "sampler")
    with pytest.raises(ValueError, match="takes no keys"):
        stream_seed(0, "design", 1)
