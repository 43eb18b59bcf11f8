# Shared helpers of the rule files: the effective config, chunking, config slices.
import hashlib
import os
import sys
from pathlib import Path

import yaml

from shockcal.design import chunk_fingerprints, planned_design


def _write_if_changed(path, text):
    """Write `path` only when its content changes (every job re-reads the Snakefile)."""
    path = Path(path)
    if not path.exists() or path.read_text() != text:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)


# Rules call the `shockcal` console script: find it next to the Python running snakemake even when
# that environment is not activated (`.venv/bin/snakemake ...`); a conda env, when used, comes first.
os.environ["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])

# The merged config (configfile + --configfile + --config) that every shockcal call reads, named by
# its content so a dry run with other settings never rewrites the file running jobs read. It is not
# a rule input: reruns follow each rule's params slice, never this file's mtime.
_EFFECTIVE_TEXT = yaml.safe_dump(config, sort_keys=True)
EFFECTIVE_CONFIG = f"{RESULTS}/config/effective-{hashlib.sha256(_EFFECTIVE_TEXT.encode()).hexdigest()[:12]}.yaml"
_write_if_changed(EFFECTIVE_CONFIG, _EFFECTIVE_TEXT)

CHUNK_SIZE = config["simulate"]["chunk_size"]
CHUNK_DIGESTS = chunk_fingerprints(planned_design(config), CHUNK_SIZE)
CHUNKS = list(range(len(CHUNK_DIGESTS)))


def chunk_rows(wildcards):
    """The design-row slice of one chunk, as `shockcal simulate --rows` takes it."""
    start = int(wildcards.chunk) * CHUNK_SIZE
    return f"{start}:{start + CHUNK_SIZE}"


def physics_slice(shot):
    """What a hydrocode run of `shot` depends on besides its design rows."""
    spec = config["shots"][shot]
    geometry = {k: spec[k] for k in ("flyer_mm", "target_mm", "velocity_input", "shear_modulus_inputs")}
    return {"material": config["material"], "hydro": config["hydro"], "shot": geometry}


def log_file(name):
    return f"{RESULTS}/logs/{name}.log"


def benchmark_file(name):
    return f"{RESULTS}/benchmarks/{name}.tsv"
