# Shared set-up: validated configuration, the case list and output locations.
from demcal.cases import TESTS, case_ids, case_row, design_from_config
from demcal.config import validate_config

validate_config(config, source=", ".join(str(f) for f in workflow.configfiles) or "config")

RESULTS = "results"
LOGS = "logs"
CONDA_ENV = "../envs/demcal.yaml"
DESIGN_TABLE = f"{RESULTS}/design/cases.csv"
DATASET = f"{RESULTS}/bulk/dataset.csv"
BULK_OUTPUTS = {"shear_cell": ["mu_psh", "mu_sh", "rho_b"], "angle_of_repose": ["aor"]}
IDENTIFIED = f"{RESULTS}/identification/identified_parameters.json"

# The design is a pure function of the configuration, so the case ids are known when the
# workflow is parsed; wildcards carry these ids, never floats.
DESIGN = design_from_config(config)
CASES = {test: case_ids(config, DESIGN, test) for test in TESTS}


def resource(kind, key, default):
    """A per-rule-kind resource from the config's `resources` section, if present."""
    return config.get("resources", {}).get(kind, {}).get(key, default)


def case_path(stage, test, case, name):
    return f"{RESULTS}/{stage}/{test}/{case}/{name}"


wildcard_constraints:
    test="shear_cell|angle_of_repose",
    case=r"[A-Za-z0-9]+(_s\d+)?",
    stage="cases|verification|discrepancy/probes|discrepancy/extended|discrepancy/verification",
    output="mu_psh|mu_sh|rho_b|aor",
OUTPUTS_TRAINED = ["mu_psh", "mu_sh", "rho_b", "aor"]
VERIFICATION_CASES = {
    "shear_cell": [f"identified_s{k + 1}" for k in range(len(config["shear_cell"]["normal_stresses"]))],
    "angle_of_repose": ["identified"],
}
