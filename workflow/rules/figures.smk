# figures rules (see docs/workflow.md)
