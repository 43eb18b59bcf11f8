# emulator rules (see docs/workflow.md)
