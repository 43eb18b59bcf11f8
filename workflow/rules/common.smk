# The plan's answers in the forms rules take (the plan: src/shockcal/study/workflow_plan.py, PLAN in the Snakefile).


def run_set_settings(stage):
    """The rule param of `stage`'s config slice for the job's shot (a candidate's stage for a candidate)."""
    return lambda w: PLAN.stage_settings(stage, w.shot)


def simulations(run_set, shot):
    """Every simulation chunk of one run set's shot."""
    return expand(rules.simulate.output[0], run_set=run_set, shot=shot, chunk=PLAN.run_set_chunks[run_set])
