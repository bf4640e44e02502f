# Shared set-up: validated configuration and output locations.
from demcal.config import validate_config

validate_config(config, source=", ".join(str(f) for f in workflow.configfiles) or "config")

RESULTS = "results"
LOGS = "logs"
DESIGN_TABLE = f"{RESULTS}/design/cases.csv"
CONDA_ENV = "../envs/demcal.yaml"
