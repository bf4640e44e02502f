# Stage 5: screen the candidate grid against the measurements; Table 5, Figs. 6-9, the
# identified parameter set, and a verification DEM run of both tests at that set on each engine
# of verification.engines.

FIGURES = {
    "fig6": "fig6_box_ssc.png",
    "fig7": "fig7_density_ssc.png",
    "fig8": "fig8_box_aor.png",
    "fig9": "fig9_box_ssc_aor.png",
}


rule identify:
    input:
        models=expand(f"{RESULTS}/surrogates/{{output}}/model.pt", output=OUTPUTS_TRAINED),
        # surrogate.screen_with may pick the process or the plane by its Table 4 row
        processes=expand(f"{RESULTS}/surrogates/{{output}}/process.json", output=OUTPUTS_TRAINED),
        linears=expand(f"{RESULTS}/surrogates/{{output}}/linear.json", output=OUTPUTS_TRAINED),
        tables=expand(f"{RESULTS}/surrogates/{{output}}/table4.csv", output=OUTPUTS_TRAINED),
        experiment=config["experiment"],
        # for the first line of Table 5: can the model reach the measurement at all?
        dataset=DATASET,
        # A sequential study screened with these networks in its last round: taken over.
        screened=lambda wc: (
            round_path(last_round(), "identification/identified_parameters.json")
            if SEQUENTIAL
            else []
        ),
    output:
        table5=report(
            f"{RESULTS}/identification/table5.md",
            category="Identification",
            caption="../report/table5.rst",
        ),
        table5_csv=f"{RESULTS}/identification/table5.csv",
        identified=IDENTIFIED,
        material=f"{RESULTS}/identification/material.in",
        **{
            key: report(
                f"{RESULTS}/identification/{name}",
                category="Identification",
                caption=f"../report/{key}.rst",
            )
            for key, name in FIGURES.items()
        },
    log:
        f"{LOGS}/identification/identify.log",
    params:
        outputs=OUTPUTS_TRAINED,
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


rule render_verification:
    input:
        identified=IDENTIFIED,
    output:
        deck=f"{RESULTS}/verification/{{engine}}/{{test}}/{{case}}/in.{{test}}",
        info=f"{RESULTS}/verification/{{engine}}/{{test}}/{{case}}/case.json",
    log:
        f"{LOGS}/render/verification/{{engine}}/{{test}}/{{case}}.log",
    priority: run_priority  # that of its run (simulate.smk)
    localrule: True
    conda:
        CONDA_ENV
    script:
        "../../scripts/render_verification.py"


rule verification_table:
    input:
        # One list of bulk files per engine, named bulk_<engine>.
        **{
            f"bulk_{engine}": lambda wildcards, engine=engine: verification_bulk_files(engine)
            for engine in VERIFICATION_ENGINES
        },
        experiment=config["experiment"],
        identified=verified_set,
    output:
        table=report(
            f"{RESULTS}/verification/verification.md",
            category="Identification",
            caption="../report/verification.rst",
        ),
        csv=f"{RESULTS}/verification/verification.csv",
    log:
        f"{LOGS}/verification/verification_table.log",
    params:
        tolerance=config["screening"]["tolerance"],
        engines=VERIFICATION_ENGINES,
        threads=VERIFICATION_THREADS,
    localrule: True
    conda:
        CONDA_ENV
    script:
        "../../scripts/verification_table.py"


# The first verification engine's first case of each test, drawn: the settled heap, the shear
# cell at the end of the pre-shear, and mu(t) with the windows the readout averaged.
VERIFICATION_PICTURES = {
    "heap": "heap.png",
    "shear_cell": "shear_cell.png",
    "mu_series": "mu_series.png",
}


rule verification_pictures:
    input:
        **{
            test: lambda wildcards, test=test: next(
                path
                for path in verification_bulk_files(next(iter(VERIFICATION_ENGINES)))
                if f"/{test}/{VERIFICATION_CASES[test][0]}/" in path
            )
            for test in TESTS
        },
    output:
        **{
            key: report(
                f"{RESULTS}/verification/pictures/{name}",
                category="Identification",
                caption="../report/verification_pictures.rst",
            )
            for key, name in VERIFICATION_PICTURES.items()
        },
    log:
        f"{LOGS}/verification/verification_pictures.log",
    localrule: True
    conda:
        CONDA_ENV
    script:
        "../../scripts/verification_pictures.py"
