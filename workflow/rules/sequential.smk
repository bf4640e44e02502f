# Sequential calibration (sequential.enabled, docs/sequential.md): the design runs in rounds.
# Round r: its DEM cases (results/cases/, ids continuing the numbering) -> the dataset of all
# runs so far -> surrogates -> screening -> a verification DEM run at the identified mean set
# -> the round record with the stopping decision (a checkpoint) -> the next round's sets.
# After the last round its dataset becomes results/bulk/dataset.csv and the usual stages follow.
# Helper functions (round_path, last_round, ...) are in common.smk.

SEQ_REPORT = "Sequential calibration"


rule sequential:
    input:
        table=f"{SEQ}/rounds.csv",
        markdown=f"{SEQ}/rounds.md",
        figure=f"{SEQ}/rounds.png",
    localrule: True


rule sequential_design:
    input:
        dataset=lambda wc: previous_round(wc, "dataset.csv"),
        verification=lambda wc: round_verification_bulk(int(wc.round) - 1),
        identified=lambda wc: previous_round(wc, "identification/identified_parameters.json"),
        record=lambda wc: previous_round(wc, "state.json"),
        experiment=config["experiment"],
    output:
        design=f"{SEQ_ROUND}/design.csv",
        choices=f"{SEQ_ROUND}/choices.csv",
    log:
        f"{LOGS}/sequential/round_{{round}}/design.log",
    wildcard_constraints:
        round=r"[1-9]\d*",
    resources:
        runtime=resource("analysis", "runtime", 10),
    params:
        constants=NETWORK_CONSTANTS,
    conda:
        CONDA_ENV
    script:
        "../../scripts/sequential_design.py"


rule sequential_dataset:
    input:
        bulk=lambda wc: round_case_bulk(int(wc.round)),
        previous=lambda wc: previous_round(wc, "dataset.csv"),
        verification=lambda wc: round_verification_bulk(int(wc.round) - 1),
    output:
        dataset=f"{SEQ_ROUND}/dataset.csv",
        failed=f"{SEQ_ROUND}/failed_cases.csv",
    log:
        f"{LOGS}/sequential/round_{{round}}/dataset.log",
    wildcard_constraints:
        round=r"\d+",
    localrule: True
    conda:
        CONDA_ENV
    script:
        "../../scripts/sequential_dataset.py"


rule sequential_train_surrogate:
    input:
        dataset=f"{SEQ_ROUND}/dataset.csv",
    output:
        model=f"{SEQ_ROUND}/surrogates/{{output}}/model.pt",
        table4=f"{SEQ_ROUND}/surrogates/{{output}}/table4.csv",
        process=f"{SEQ_ROUND}/surrogates/{{output}}/process.json",
        linear=f"{SEQ_ROUND}/surrogates/{{output}}/linear.json",
    log:
        f"{LOGS}/sequential/round_{{round}}/surrogates/{{output}}.log",
    wildcard_constraints:
        round=r"\d+",
    params:
        settings=config["surrogate"],
    threads: 1
    resources:
        runtime=resource("training", "runtime", 30),
        mem_mb=resource("training", "mem_mb", 2000),
    conda:
        CONDA_ENV
    script:
        "../../scripts/train_surrogate.py"


checkpoint sequential_identify:
    input:
        models=lambda wc: [
            round_path(wc.round, f"surrogates/{o}/model.pt") for o in ROUND_OUTPUTS
        ],
        processes=lambda wc: [
            round_path(wc.round, f"surrogates/{o}/process.json") for o in ROUND_OUTPUTS
        ],
        linears=lambda wc: [
            round_path(wc.round, f"surrogates/{o}/linear.json") for o in ROUND_OUTPUTS
        ],
        experiment=config["experiment"],
        dataset=f"{SEQ_ROUND}/dataset.csv",
    output:
        table5=f"{SEQ_ROUND}/identification/table5.md",
        table5_csv=f"{SEQ_ROUND}/identification/table5.csv",
        identified=f"{SEQ_ROUND}/identification/identified_parameters.json",
        material=f"{SEQ_ROUND}/identification/material.in",
        **{key: f"{SEQ_ROUND}/identification/{name}" for key, name in FIGURES.items()},
    log:
        f"{LOGS}/sequential/round_{{round}}/identify.log",
    wildcard_constraints:
        round=r"\d+",
    params:
        outputs=ROUND_OUTPUTS,
        screening=config["screening"],
        constants=NETWORK_CONSTANTS,
    threads: config["screening"]["threads"]
    resources:
        runtime=resource("training", "runtime", 30),
        mem_mb=resource("training", "mem_mb", 4000),
    conda:
        CONDA_ENV
    script:
        "../../scripts/identify.py"


rule sequential_render_verification:
    input:
        identified=f"{SEQ_ROUND}/identification/identified_parameters.json",
    output:
        deck=f"{SEQ_ROUND}/verification/{{test}}/{{case}}/in.{{test}}",
        info=f"{SEQ_ROUND}/verification/{{test}}/{{case}}/case.json",
    log:
        f"{LOGS}/render/sequential/round_{{round}}/{{test}}/{{case}}.log",
    priority: run_priority  # that of its run (simulate.smk)
    wildcard_constraints:
        round=r"\d+",
    localrule: True
    conda:
        CONDA_ENV
    script:
        "../../scripts/render_verification.py"


checkpoint sequential_state:
    input:
        identified=f"{SEQ_ROUND}/identification/identified_parameters.json",
        verification=lambda wc: round_verification_bulk(int(wc.round)),
        table4=lambda wc: [
            round_path(wc.round, f"surrogates/{o}/table4.csv") for o in ROUND_OUTPUTS
        ],
        previous=lambda wc: previous_round(wc, "state.json"),
        experiment=config["experiment"],
    output:
        record=f"{SEQ_ROUND}/state.json",
        verification=f"{SEQ_ROUND}/verification.md",
    log:
        f"{LOGS}/sequential/round_{{round}}/state.log",
    wildcard_constraints:
        round=r"\d+",
    localrule: True
    params:
        outputs=ROUND_OUTPUTS,
    conda:
        CONDA_ENV
    script:
        "../../scripts/sequential_state.py"


rule sequential_rounds:
    input:
        records=lambda wc: [round_path(r, "state.json") for r in range(last_round() + 1)],
        identified=lambda wc: [
            round_path(r, "identification/identified_parameters.json")
            for r in range(last_round() + 1)
        ],
    output:
        table=f"{SEQ}/rounds.csv",
        markdown=report(
            f"{SEQ}/rounds.md", category=SEQ_REPORT, caption="../report/sequential.rst"
        ),
        figure=report(
            f"{SEQ}/rounds.png", category=SEQ_REPORT, caption="../report/sequential.rst"
        ),
    log:
        f"{LOGS}/sequential/rounds.log",
    localrule: True
    conda:
        CONDA_ENV
    script:
        "../../scripts/sequential_rounds.py"


rule sequential_final_dataset:
    input:
        dataset=lambda wc: round_path(last_round(), "dataset.csv"),
        failed=lambda wc: round_path(last_round(), "failed_cases.csv"),
        # the report of the rounds comes with the dataset of a sequential study
        rounds=f"{SEQ}/rounds.md",
    output:
        dataset=report(DATASET, category="Bulk values", caption="../report/dataset.rst"),
        failed=report(
            f"{RESULTS}/bulk/failed_cases.csv",
            category="Bulk values",
            caption="../report/failed_cases.rst",
        ),
    log:
        f"{LOGS}/bulk/collect_dataset.log",
    localrule: True
    conda:
        CONDA_ENV
    shell:
        # The last round's data: the final surrogates and identification repeat that round's.
        "(cp {input.dataset} {output.dataset} && cp {input.failed} {output.failed}) > {log} 2>&1"
