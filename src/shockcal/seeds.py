"""Named random streams of a study, all from one `numpy.random.SeedSequence(study.seed)`.

Every stage that draws random numbers takes its seed here, by stream name, so no two stages share
a stream and adding a stream moves no other. The design keeps the root sequence itself
(`default_rng(study.seed)`), so a study's Latin hypercube is the one its seed always gave; every
other stream is a child of the root (`SeedSequence.spawn` order = `STREAMS` order), optionally
keyed further (an emulator block index, a calibration's shots).

| stream | used by |
|---|---|
| design | the training Latin hypercube (`shockcal design`) |
| emulator | hyperparameter starts, fit subset and K-fold folds, one key per emulator block |
| calibration | the nested sampler and the resampling of its draws, keyed by the calibrated shots |
| check | synthetic-truth trials (truths, noise, per-trial sampler seeds), keyed by shots |
| check_design | the Latin hypercube of the hydrocode-truth check runs |
| posterior_draws | the posterior rows run through the hydrocode for predictions |
| figures | which training traces the history figures draw |
| design_extension | the column of an input only a later shot reads (`design.base_shots`), keyed by shot and input |
| sensitivity | the Sobol sequence's scrambling and the bootstrap of the Sobol indices |
| readout | the noise replicates of a measured record's read-out bootstrap (`shockcal observed`), keyed by shot |
| next_shot | candidates' draws ("draws"), gains ("eig", name); the check's truths ("check_truths"), noise ("check_noise") |
| replicate | a calibration's runs after its first (`calibration.replicates`), keyed by run, rooted at the calibration's seed |
| waves | a sequential study's later waves: the posterior pool of wave k ("pool", k) |
| check_posterior | the joint-posterior draws the posterior-truth check takes as truths (`shockcal predict --stream`) |
| new_shot | a new shot's runs (`design.new_shots`): the posterior pool, keyed by shot; its own inputs, by shot and input |
| verify | the joint-posterior draws the hydrocode's verdict runs (`make verify`; `shockcal predict --stream`) |
"""
from __future__ import annotations

import zlib

import numpy as np

STREAMS = ("emulator", "calibration", "check", "check_design", "posterior_draws", "figures", "design_extension",
           "sensitivity", "readout", "next_shot", "replicate", "waves", "check_posterior",
           "new_shot", "verify")


def stream_seed(study_seed: int, name: str, *keys: int | str) -> int:
    """The integer seed (0 <= seed < 2**32) of stream `name`, further keyed by `keys` (ints, or
    strings hashed with CRC-32), for `np.random.default_rng` or any library taking an int seed."""
    if name == "design":
        if keys:
            raise ValueError("the design stream is the root sequence and takes no keys")
        return int(study_seed)
    if name not in STREAMS:
        raise ValueError(f"unknown random stream {name!r}; known: design, {', '.join(STREAMS)}")
    spawn_key = (STREAMS.index(name), *(zlib.crc32(k.encode()) if isinstance(k, str) else int(k) for k in keys))
    return int(np.random.SeedSequence(study_seed, spawn_key=spawn_key).generate_state(1, np.uint32)[0])
