# Stage 2: render one deck per DEM case, run it with the configured engine, extract its bulk
# values.
from demcal.bulk.dataset import write_case_rows


rule render_case:
    input:
        unpack(case_design),
    output:
        deck=f"{RESULTS}/cases/{{test}}/{{case}}/in.{{test}}",
        info=f"{RESULTS}/cases/{{test}}/{{case}}/case.json",
    log:
        f"{LOGS}/render/{{test}}/{{case}}.log",
    # The run's priority: a run can start first only if its deck was rendered first.
    priority: run_priority
    localrule: True
    run:
        # In-process: a new interpreter per case would cost more than the rendering.
        render_study_case(wildcards, input, output.deck, log[0])


# Wall-clock time, memory and CPU of every engine run (the study's cases: rule run_times).
CASE_BENCHMARK = f"{RESULTS}/benchmarks/{{stage}}/{{test}}/{{case}}.tsv"


rule run_case:
    input:
        deck=f"{RESULTS}/{{stage}}/{{test}}/{{case}}/in.{{test}}",
        info=f"{RESULTS}/{{stage}}/{{test}}/{{case}}/case.json",
    output:
        status=f"{RESULTS}/{{stage}}/{{test}}/{{case}}/status.json",
    log:
        f"{LOGS}/run/{{stage}}/{{test}}/{{case}}.log",
    benchmark:
        CASE_BENCHMARK
    params:
        command=lambda wildcards: engine_command(wildcards.stage),
    threads: lambda wildcards: engine_threads(wildcards.stage)
    priority: run_priority
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
    localrule: True
    run:
        write_case_rows(wildcards.test, input.info, params.p_values, output.bulk, config, log[0])
