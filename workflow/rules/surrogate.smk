# Stage 4: one network per bulk value (hidden-size sweep), baselines, their cross-validation by
# parameter set (surrogate.cv_folds) and Table 4.


rule train_surrogate:
    input:
        dataset=DATASET,
        # A sequential study trained these networks in its last round: they are taken over.
        trained=lambda wc: (
            round_path(last_round(), f"surrogates/{wc.output}/model.pt")
            if SEQUENTIAL and wc.output in ROUND_OUTPUTS
            else []
        ),
    output:
        model=f"{RESULTS}/surrogates/{{output}}/model.pt",
        table4=f"{RESULTS}/surrogates/{{output}}/table4.csv",
        process=f"{RESULTS}/surrogates/{{output}}/process.json",
        linear=f"{RESULTS}/surrogates/{{output}}/linear.json",
        sweep=f"{RESULTS}/surrogates/{{output}}/sweep.csv",
        cv_folds=f"{RESULTS}/surrogates/{{output}}/cv_folds.csv",
        parity_ann=report(
            f"{RESULTS}/surrogates/{{output}}/parity_ann.png",
            category="Surrogates",
            subcategory="{output}",
            caption="../report/parity.rst",
        ),
        parity_bayesian=report(
            f"{RESULTS}/surrogates/{{output}}/parity_bayesian.png",
            category="Surrogates",
            subcategory="{output}",
            caption="../report/parity.rst",
        ),
        parity_gaussian=report(
            f"{RESULTS}/surrogates/{{output}}/parity_gaussian.png",
            category="Surrogates",
            subcategory="{output}",
            caption="../report/parity.rst",
        ),
        r2_size=report(
            f"{RESULTS}/surrogates/{{output}}/r2_vs_hidden_size.png",
            category="Surrogates",
            subcategory="{output}",
            caption="../report/r2_size.rst",
        ),
    log:
        f"{LOGS}/surrogates/{{output}}.log",
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


rule table4:
    input:
        tables=expand(f"{RESULTS}/surrogates/{{output}}/table4.csv", output=OUTPUTS_TRAINED),
        sweeps=expand(f"{RESULTS}/surrogates/{{output}}/sweep.csv", output=OUTPUTS_TRAINED),
        # The acceptance tolerance applies to the measured values; only this cheap rule reruns
        # when they change.
        experiment=config["experiment"],
    output:
        markdown=report(
            f"{RESULTS}/surrogates/table4.md", category="Surrogates", caption="../report/table4.rst"
        ),
        csv=f"{RESULTS}/surrogates/table4.csv",
    log:
        f"{LOGS}/surrogates/table4.log",
    params:
        outputs=OUTPUTS_TRAINED,
        tolerance=config["screening"]["tolerance"],
    localrule: True
    conda:
        CONDA_ENV
    script:
        "../../scripts/write_table4.py"
