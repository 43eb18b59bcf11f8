"""Progress of long jobs: a few readable lines in a log file, a bar on a terminal, results unchanged."""

import io
import logging

import numpy as np

from shockcal.progress import progress
from shockcal.study.adapters import shot_mapping


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_a_log_file_gets_a_start_line_periodic_lines_and_an_end_line(caplog, monkeypatch):
    now = [0.0]
    monkeypatch.setattr("tqdm.std.time", lambda: now[0])        # tqdm's clock: 10 s per run below
    log = logging.getLogger("shockcal.test")
    caplog.set_level(logging.INFO, logger="shockcal.test")
    stream = io.StringIO()                                      # a log file: not a terminal
    done = []
    for run in progress(range(20), 20, "shot 104S", "run", log, interval_s=30, stream=stream):
        now[0] += 10.0
        done.append(run)
    assert done == list(range(20))
    lines = [r.getMessage() for r in caplog.records]
    assert stream.getvalue() == ""                              # everything went through the logger
    assert lines[0].startswith("shot 104S: 0/20 runs (0%)") and lines[-1].startswith("shot 104S: 20/20 runs (100%)")
    assert len(lines) == 8, lines                               # 200 s: a line per 30 s, not one per run
    assert lines[1] == "shot 104S: 3/20 runs (15%), 00:30 elapsed, 02:50 left, 10.00s/run"
    assert all("\r" not in line and " left, " in line for line in lines)
    assert len(set(lines)) == len(lines)                        # the end is not repeated


def test_quiet_where_logging_is_off(caplog):
    log = logging.getLogger("shockcal.test.quiet")
    caplog.set_level(logging.WARNING, logger="shockcal.test.quiet")
    assert list(progress(range(3), 3, "x", "run", log, stream=io.StringIO())) == [0, 1, 2]
    assert not caplog.records


def test_a_terminal_gets_tqdms_bar():
    terminal = Terminal()
    assert list(progress(range(5), 5, "shot 104S", "run", logging.getLogger("shockcal.test"), stream=terminal)) == \
        list(range(5))
    assert "\r" in terminal.getvalue() and "5/5" in terminal.getvalue()


def test_a_simulate_chunk_logs_its_progress(paper_config, caplog, monkeypatch):
    from shockcal.design.tables import latin_hypercube
    from shockcal.simulators.builtin import simulate_design
    from shockcal.study.adapters import hydro_inputs
    from shockcal.study.config import prior_bounds

    def no_hydrocode(*args):
        raise FloatingPointError("not run in this test")        # recorded as a failed run

    monkeypatch.setattr("shockcal.simulators.builtin.run_shot", no_hydrocode)
    caplog.set_level(logging.INFO, logger="shockcal.simulators.builtin")
    design = latin_hypercube(prior_bounds(paper_config), 3, seed=1)
    simulate_design(design, shot_mapping(paper_config, "104S"),
                    *hydro_inputs(paper_config, paper_config["shots"]["104S"]))
    assert any(r.getMessage().startswith("shot 104S: 3/3 runs (100%)") for r in caplog.records)


def test_sampler_progress_lines_leave_the_draws_unchanged(caplog, monkeypatch):
    from shockcal.inference.sampler import nested_sample

    def run():
        # the sampler's least settings (MIN_N_LIVE, MIN_N_EFF): the draws' equality does not depend on the run's size
        return nested_sample(lambda u: 4 * u - 2, lambda x: -0.5 * np.sum(x**2, axis=1) / 0.3**2, 2, n_live=50,
                             n_eff=100, seed=7)

    caplog.set_level(logging.INFO, logger="shockcal.inference.sampler")
    quiet = run()
    assert not caplog.records                                   # shorter than 30 s: no line
    monkeypatch.setattr("shockcal.progress.LOG_INTERVAL_S", 0.0)
    loud = run()
    assert any(r.getMessage().startswith("nautilus: ") for r in caplog.records)
    assert np.array_equal(quiet.points, loud.points) and np.array_equal(quiet.log_weight, loud.log_weight)
