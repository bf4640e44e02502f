# Discrepancy workflow: find where the calibrated model and the measurements disagree, name the
# missing physical effect with DEM probe runs around the best point (bootstrap tests), add it to
# the model (extended design, new surrogates, recalibration) and show the gap before and after
# with replicate DEM runs, also at held-out loads that no step before saw.
# Target: `snakemake --cores 2 discrepancy`. If nothing is missing it stops after Find.

from demcal.discrepancy.plan import DiscrepancyPlan
from demcal.discrepancy.runs import render_discrepancy_run

DISC = f"{RESULTS}/discrepancy"
DISC_PLAN = DiscrepancyPlan.from_config(config, RESULTS)
DISC_REPORT = "Discrepancy"


rule discrepancy:
    input:
        find=f"{DISC}/find.md",
        ranking_table=f"{DISC}/ranking.csv",
        ranking=f"{DISC}/ranking.md",
        gap_table=f"{DISC}/gap_before_after.csv",
        gap_figure=f"{DISC}/gap_before_after.png",
        verification=f"{DISC}/verification.md",
        summary=f"{DISC}/summary.json",
    localrule: True


checkpoint discrepancy_find:
    input:
        models=DISC_PLAN.model_files("current"),
        experiment=config["experiment"],
    output:
        table=f"{DISC}/find.csv",
        record=f"{DISC}/find.json",
        markdown=report(
            f"{DISC}/find.md", category=DISC_REPORT, caption="../report/discrepancy_find.rst"
        ),
    log:
        f"{LOGS}/discrepancy/find.log",
    params:
        outputs=DISC_PLAN.outputs,
    threads: 1
    resources:
        runtime=resource("analysis", "runtime", 10),
        mem_mb=resource("analysis", "mem_mb", 2000),
    conda:
        CONDA_ENV
    script:
        "../../scripts/discrepancy_find.py"


rule discrepancy_render_probe:
    input:
        record=f"{DISC}/find.json",
    output:
        deck=f"{DISC}/probes/{{test}}/{{case}}/in.{{test}}",
        info=f"{DISC}/probes/{{test}}/{{case}}/case.json",
    log:
        f"{LOGS}/render/discrepancy/probes/{{test}}/{{case}}.log",
    priority: run_priority  # that of its run (simulate.smk)
    localrule: True
    run:
        # In-process, like render_case: a new interpreter per run costs more than rendering.
        render_discrepancy_run(
            "probe", wildcards.test, wildcards.case, config, input.record, output.deck, log[0]
        )


# The leading candidates' own best fits, where they are probed again (discrepancy.reprobe): a
# response measured at theta* misleads where the missing effect drags theta* far away.
checkpoint discrepancy_lead:
    input:
        probes=lambda wc: DISC_PLAN.probe_bulk(checkpoints.discrepancy_find.get().output.record),
        find=f"{DISC}/find.json",
        models=DISC_PLAN.model_files("current"),
        experiment=config["experiment"],
    output:
        record=f"{DISC}/lead.json",
    log:
        f"{LOGS}/discrepancy/lead.log",
    params:
        outputs=DISC_PLAN.outputs,
    threads: 1
    resources:
        runtime=resource("analysis", "runtime", 10),
        mem_mb=resource("analysis", "mem_mb", 2000),
    conda:
        CONDA_ENV
    script:
        "../../scripts/discrepancy_lead.py"


rule discrepancy_render_reprobe:
    input:
        record=f"{DISC}/lead.json",
    output:
        deck=f"{DISC}/reprobes/{{test}}/{{case}}/in.{{test}}",
        info=f"{DISC}/reprobes/{{test}}/{{case}}/case.json",
    log:
        f"{LOGS}/render/discrepancy/reprobes/{{test}}/{{case}}.log",
    priority: run_priority  # that of its run (simulate.smk)
    localrule: True
    run:
        render_discrepancy_run(
            "reprobe", wildcards.test, wildcards.case, config, input.record, output.deck, log[0]
        )


checkpoint discrepancy_rank:
    input:
        probes=lambda wc: DISC_PLAN.probe_bulk(checkpoints.discrepancy_find.get().output.record),
        lead=f"{DISC}/lead.json",
        reprobes=lambda wc: DISC_PLAN.reprobe_bulk(
            checkpoints.discrepancy_lead.get().output.record
        ),
        find=f"{DISC}/find.json",
        models=DISC_PLAN.model_files("current"),
        experiment=config["experiment"],
    output:
        table=report(
            f"{DISC}/ranking.csv", category=DISC_REPORT, caption="../report/discrepancy_ranking.rst"
        ),
        markdown=report(
            f"{DISC}/ranking.md", category=DISC_REPORT, caption="../report/discrepancy_ranking.rst"
        ),
        record=f"{DISC}/ranking.json",
        probes=f"{DISC}/probes.csv",
        reprobes=f"{DISC}/reprobes.csv",
        design=f"{DISC}/extended/design.csv",
    log:
        f"{LOGS}/discrepancy/rank.log",
    params:
        outputs=DISC_PLAN.outputs,
    threads: 1
    resources:
        runtime=resource("analysis", "runtime", 10),
        mem_mb=resource("analysis", "mem_mb", 2000),
    conda:
        CONDA_ENV
    script:
        "../../scripts/discrepancy_rank.py"


rule discrepancy_render_extended:
    input:
        record=f"{DISC}/ranking.json",
        design=f"{DISC}/extended/design.csv",
    output:
        deck=f"{DISC}/extended/{{test}}/{{case}}/in.{{test}}",
        info=f"{DISC}/extended/{{test}}/{{case}}/case.json",
    log:
        f"{LOGS}/render/discrepancy/extended/{{test}}/{{case}}.log",
    priority: run_priority  # that of its run (simulate.smk)
    localrule: True
    run:
        render_discrepancy_run(
            "extended",
            wildcards.test,
            wildcards.case,
            config,
            input.record,
            output.deck,
            log[0],
            input.design,
        )


rule discrepancy_dataset:
    input:
        extended=lambda wc: DISC_PLAN.extended_bulk(checkpoints.discrepancy_rank.get().output.design),
        # Every run at theta* and at the leaders' best fits: all are rows of the extended model.
        probes=lambda wc: (
            DISC_PLAN.probe_bulk(checkpoints.discrepancy_find.get().output.record)
            + DISC_PLAN.reprobe_bulk(checkpoints.discrepancy_lead.get().output.record)
        ),
        ranking=f"{DISC}/ranking.json",
        dataset=DATASET,
    output:
        dataset=f"{DISC}/extended/dataset.csv",
    log:
        f"{LOGS}/discrepancy/dataset.log",
    params:
        tests=DISC_PLAN.tests,
    threads: 1
    resources:
        runtime=resource("analysis", "runtime", 10),
        mem_mb=resource("analysis", "mem_mb", 2000),
    conda:
        CONDA_ENV
    script:
        "../../scripts/discrepancy_dataset.py"


rule discrepancy_train:
    input:
        dataset=f"{DISC}/extended/dataset.csv",
        ranking=f"{DISC}/ranking.json",
    output:
        model=f"{DISC}/surrogates/{{output}}/model.pt",
    log:
        f"{LOGS}/discrepancy/train_{{output}}.log",
    threads: 1
    resources:
        runtime=resource("training", "runtime", 30),
        mem_mb=resource("training", "mem_mb", 2000),
    conda:
        CONDA_ENV
    script:
        "../../scripts/discrepancy_train.py"


rule discrepancy_recalibrate:
    input:
        models=DISC_PLAN.model_files("extended"),
        ranking=f"{DISC}/ranking.json",
        experiment=config["experiment"],
    output:
        table=f"{DISC}/find_after.csv",
        record=f"{DISC}/recalibration.json",
        markdown=report(
            f"{DISC}/find_after.md",
            category=DISC_REPORT,
            caption="../report/discrepancy_recalibration.rst",
        ),
    log:
        f"{LOGS}/discrepancy/recalibrate.log",
    params:
        outputs=DISC_PLAN.outputs,
    threads: config["screening"]["threads"]
    resources:
        runtime=resource("training", "runtime", 30),
        mem_mb=resource("training", "mem_mb", 4000),
    conda:
        CONDA_ENV
    script:
        "../../scripts/discrepancy_recalibrate.py"


rule discrepancy_render_verification:
    input:
        record=f"{DISC}/recalibration.json",
    output:
        deck=f"{DISC}/verification/{{test}}/{{case}}/in.{{test}}",
        info=f"{DISC}/verification/{{test}}/{{case}}/case.json",
    log:
        f"{LOGS}/render/discrepancy/verification/{{test}}/{{case}}.log",
    priority: run_priority  # that of its run (simulate.smk)
    localrule: True
    run:
        render_discrepancy_run(
            "verification", wildcards.test, wildcards.case, config, input.record, output.deck, log[0]
        )


rule discrepancy_show:
    input:
        unpack(
            lambda wc: DISC_PLAN.show_inputs(
                checkpoints.discrepancy_find.get().output.record,
                checkpoints.discrepancy_rank.get().output.record,
            )
        ),
        find=f"{DISC}/find.json",
        find_table=f"{DISC}/find.csv",
        ranking=f"{DISC}/ranking.json",
        experiment=config["experiment"],
    output:
        table=report(
            f"{DISC}/gap_before_after.csv",
            category=DISC_REPORT,
            caption="../report/discrepancy_gap.rst",
        ),
        figure=report(
            f"{DISC}/gap_before_after.png",
            category=DISC_REPORT,
            caption="../report/discrepancy_gap.rst",
        ),
        verification=report(
            f"{DISC}/verification.md",
            category=DISC_REPORT,
            caption="../report/discrepancy_verification.rst",
        ),
        summary=f"{DISC}/summary.json",
    log:
        f"{LOGS}/discrepancy/show.log",
    threads: 1
    resources:
        runtime=resource("plotting", "runtime", 10),
        mem_mb=resource("plotting", "mem_mb", 2000),
    conda:
        CONDA_ENV
    script:
        "../../scripts/discrepancy_show.py"
