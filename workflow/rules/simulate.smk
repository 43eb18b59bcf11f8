# simulate rules (see docs/workflow.md)
