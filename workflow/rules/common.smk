# Shared set-up: validated configuration, the case list and output locations.
from demcal.design.cases import TESTS, case_ids, case_row, design_from_config, verification_case_ids
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


def resource(kind, key, default):
    """Resource `key` for jobs of `kind` at the study scale (resources.<profile>.<kind>)."""
    per_profile = config.get("resources", {}).get(config["profile"], {})
    return per_profile.get(kind, {}).get(key, default)

