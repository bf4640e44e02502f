# Shared set-up: validated configuration, the case list and output locations.
from demcal.core.parameters import TESTS
from demcal.design.cases import (
    case_ids,
    case_row,
    design_from_config,
    verification_case_ids,
    verification_engines,
    verification_threads,
)
from demcal.core.config import validate_config

validate_config(config, source=", ".join(str(f) for f in workflow.configfiles) or "config")

RESULTS = "results"
LOGS = "logs"
CONDA_ENV = "../envs/demcal.yaml"
DESIGN_TABLE = f"{RESULTS}/design/cases.csv"
DATASET = f"{RESULTS}/bulk/dataset.csv"
IDENTIFIED = f"{RESULTS}/identification/identified_parameters.json"
OUTPUTS_TRAINED = ["mu_psh", "mu_sh", "rho_b", "aor"]

# The design is a pure function of the configuration, so the case ids are known when the
# workflow is parsed; wildcards carry these ids, never floats.
DESIGN = design_from_config(config)
CASES = {test: case_ids(config, DESIGN, test) for test in TESTS}
VERIFICATION_CASES = {test: verification_case_ids(config, test) for test in TESTS}
# Engines of the verification runs (name -> command); each runs the cases in
# results/verification/<name>/.
VERIFICATION_ENGINES = verification_engines(config)
VERIFICATION_THREADS = verification_threads(config)


def engine_command(stage):
    """Command template of the engine that runs the cases of `stage`."""
    if stage.startswith("verification/"):
        return VERIFICATION_ENGINES[stage.split("/", 1)[1]]
    return config["engine"]["command"]


def engine_threads(stage):
    """Threads or MPI ranks of one run of `stage`."""
    if stage.startswith("verification/"):
        return VERIFICATION_THREADS
    return config["engine"]["threads"]


def resource(kind, key, default):
    """Resource `key` for jobs of `kind` at the study scale (resources.<profile>.<kind>)."""
    per_profile = config.get("resources", {}).get(config["profile"], {})
    return per_profile.get(kind, {}).get(key, default)

