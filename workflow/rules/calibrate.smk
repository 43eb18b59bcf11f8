# calibrate rules (see docs/workflow.md)
