# predict rules (see docs/workflow.md)
