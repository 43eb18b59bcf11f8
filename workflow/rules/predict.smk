# predict rules (issue 7): being written; the full rules are enabled once the upstream stages define
# STUDY_CONFIG, OBSERVED_FEATURES and simulation_chunks (common/features/simulate .smk).
