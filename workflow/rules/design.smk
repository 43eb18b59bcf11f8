# design rules (see docs/workflow.md)
