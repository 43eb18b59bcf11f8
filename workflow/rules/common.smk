# common rules (see docs/workflow.md)
