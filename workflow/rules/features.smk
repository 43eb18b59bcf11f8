# features rules (see docs/workflow.md)
