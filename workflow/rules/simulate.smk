# Stage 2: render one deck per DEM case and run it with the configured engine.


rule render_case:
    output:
        deck=f"{RESULTS}/cases/{{test}}/{{case}}/in.{{test}}",
        info=f"{RESULTS}/cases/{{test}}/{{case}}/case.json",
    log:
        f"{LOGS}/render/{{test}}/{{case}}.log",
    params:
        case=lambda wc: case_row(config, DESIGN, wc.test, wc.case),
    conda:
        CONDA_ENV
    localrule: True
    script:
        "../../scripts/render_case.py"


rule run_case:
    input:
        deck=f"{RESULTS}/{{stage}}/{{test}}/{{case}}/in.{{test}}",
        info=f"{RESULTS}/{{stage}}/{{test}}/{{case}}/case.json",
    output:
        status=f"{RESULTS}/{{stage}}/{{test}}/{{case}}/status.json",
    log:
        f"{LOGS}/run/{{stage}}/{{test}}/{{case}}.log",
    params:
        command=lambda wildcards: config["engine"]["command"],
    threads: config["engine"]["threads"]
    resources:
        runtime=resource("dem_case", "runtime", 60),
        mem_mb=resource("dem_case", "mem_mb", 2000),
    conda:
        CONDA_ENV
    script:
        "../../scripts/run_case.py"


rule bulk_case:
    input:
        status=f"{RESULTS}/{{stage}}/{{test}}/{{case}}/status.json",
        info=f"{RESULTS}/{{stage}}/{{test}}/{{case}}/case.json",
    output:
        bulk=f"{RESULTS}/{{stage}}/{{test}}/{{case}}/bulk.csv",
    log:
        f"{LOGS}/bulk/{{stage}}/{{test}}/{{case}}.log",
    params:
        p_values=config["shear_cell"]["P"],
    resources:
        runtime=resource("analysis", "runtime", 10),
        mem_mb=resource("analysis", "mem_mb", 1000),
    conda:
        CONDA_ENV
    script:
        "../../scripts/extract_bulk.py"
