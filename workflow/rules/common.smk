# Shared set-up: validated configuration, the case list and output locations.
import json
from functools import cache
from pathlib import Path

from demcal.core.parameters import TESTS
from demcal.design.cases import (
    CONFIGURED_ENGINE,
    case_ids,
    case_row,
    design_from_config,
    design_id,
    verification_case_ids,
    verification_engines,
    verification_threads,
)
from demcal.core.config import validate_config
from demcal.core.experiments import load_experiment
from demcal.core.rule_log import rule_log
from demcal.design.table import read_design_table
from demcal.virtual_tests.deck import particle_steps, render_case
from demcal.sequential.rounds import check_sequential, round_case_ids, round_of_case

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
# The networks' inputs that the screening holds at the study's value.
NETWORK_CONSTANTS = {
    "mu_psh": {"dCylDp": config["shear_cell"]["dCylDp"]},
    "mu_sh": {"dCylDp": config["shear_cell"]["dCylDp"]},
    "rho_b": {"dCylDp": config["shear_cell"]["dCylDp"]},
    "aor": {"dCylDp": config["angle_of_repose"]["dCylDp"]},
}
# A sequential study runs its design in rounds (sequential.smk); checked before any work starts.
SEQUENTIAL = bool(config["sequential"]["enabled"])
# The rounds train only the networks of measured values (the others once, after the last round).
ROUND_OUTPUTS = OUTPUTS_TRAINED
if SEQUENTIAL:
    check_sequential(config)
    ROUND_OUTPUTS = [
        o for o in OUTPUTS_TRAINED if o in load_experiment(config["experiment"]).outputs
    ]
SEQ = f"{RESULTS}/sequential"
SEQ_ROUND = f"{SEQ}/round_{{round}}"


def case_design(wildcards):
    """The design table of a case that a later round of a sequential study chose (none for the
    configured design, which is known when the workflow is parsed)."""
    if SEQUENTIAL:
        round_no = round_of_case(config, design_id(wildcards.case))
        if round_no > 0:
            return {"design": round_path(round_no, "design.csv")}
    return {}


def render_study_case(wildcards, rule_input, deck, log):
    """Render one DEM case of the study from its design row (its round's design table, or the
    configured design) into the directory of ``deck``."""
    design = read_design_table(rule_input.design) if "design" in rule_input.keys() else DESIGN
    with rule_log(log):
        case = case_row(config, design, wildcards.test, wildcards.case)
        render_case(wildcards.test, case, config, Path(deck).parent)


def study_case_ids(test):
    """Ids of every DEM case of one test in the study (all rounds of a sequential one)."""
    if not SEQUENTIAL:
        return CASES[test]
    return [c for r in range(last_round() + 1) for c in round_case_ids(config, r, test)]


def round_path(round_no, name):
    """A file of round ``round_no`` of a sequential study."""
    return f"{SEQ}/round_{round_no}/{name}"


def previous_round(wildcards, name):
    """File ``name`` of the round before ``wildcards.round`` (none before round 0)."""
    round_no = int(wildcards.round)
    return [round_path(round_no - 1, name)] if round_no > 0 else []


def round_case_bulk(round_no):
    """bulk.csv of every DEM case of round ``round_no``."""
    return [
        f"{RESULTS}/cases/{test}/{case}/bulk.csv"
        for test in TESTS
        for case in round_case_ids(config, round_no, test)
    ]


def round_verification_bulk(round_no):
    """bulk.csv of round ``round_no``'s verification runs; none when it identified nothing."""
    if round_no < 0:
        return []
    identified = Path(round_path(round_no, "identification/identified_parameters.json"))
    # A resumed study: Snakemake registers a finished checkpoint only for jobs it met in its
    # first pass over the DAG, so a later round's identification, finished before the run,
    # would stay a placeholder here. An identify job that reruns updates its dependants anyway.
    if not identified.is_file():
        identified = checkpoints.sequential_identify.get(round=round_no).output.identified
    if not json.loads(Path(identified).read_text()).get("parameters"):
        return []
    return verification_bulk_under(round_path(round_no, "verification"))


def verification_bulk_under(directory):
    """bulk.csv of every verification case (each replicate, each load) below ``directory``."""
    return [
        f"{directory}/{test}/{case}/bulk.csv" for test in TESTS for case in VERIFICATION_CASES[test]
    ]


def last_round():
    """The round whose record says stop (checkpoints: known once the rounds have run)."""
    round_no = 0
    while True:
        record = checkpoints.sequential_state.get(round=round_no).output.record
        if json.loads(Path(record).read_text())["stop"]:
            return round_no
        round_no += 1


def verification_bulk_files(engine):
    """bulk.csv of the verification runs of ``engine`` (call from an input function). A
    sequential study verified its last round's identified set with engine.command already:
    those runs are reused."""
    if SEQUENTIAL and engine == CONFIGURED_ENGINE:
        return round_verification_bulk(last_round())
    return verification_bulk_under(f"{RESULTS}/verification/{engine}")


def verified_set(wildcards):
    """The identified set that the verification runs used."""
    if SEQUENTIAL:
        return round_path(last_round(), "identification/identified_parameters.json")
    return IDENTIFIED


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


@cache
def design_case_cost(test, case):
    """Particle-steps of one case of the configured design (each computed once, when asked:
    a cluster job's Snakemake process needs only its own)."""
    return particle_steps(test, case_row(config, DESIGN, test, case), config)


@cache
def mean_design_cost(test):
    """Mean particle-steps of the configured design's cases of `test` (0 without any)."""
    costs = [design_case_cost(test, case) for case in CASES[test]]
    return sum(costs) / len(costs) if costs else 0.0


def run_priority(wildcards):
    """Scheduling priority of a DEM run: its particle-steps in millions, so that the longest
    runs start first and no core idles at the end of a stage while one long run finishes
    (longest-first scheduling). Cases outside the configured design (verification, later
    sequential rounds, probes) count as the design's mean run of their test."""
    if wildcards.case in CASES[wildcards.test]:
        cost = design_case_cost(wildcards.test, wildcards.case)
    else:
        cost = mean_design_cost(wildcards.test)
    return round(cost / 1e6, 3)


def resource(kind, key, default):
    """Resource `key` for jobs of `kind` at the study scale (resources.<profile>.<kind>)."""
    per_profile = config.get("resources", {}).get(config["profile"], {})
    return per_profile.get(kind, {}).get(key, default)

