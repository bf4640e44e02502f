# Industrial application (paper Figs. 10-11): the identified parameters in a sinter chute
# cooler; segregation by size in one box of a row of moving boxes.

APPLICATION = f"{RESULTS}/application"
APPLICATION_RUN = f"{APPLICATION}/run"
APPLICATION_PARAMETERS = f"{RESULTS}/identification/identified_parameters.json"


rule application_render:
    input:
        # the identified parameters, unless the config gives explicit values
        unpack(
            lambda wildcards: (
                {"params": APPLICATION_PARAMETERS}
                if config["application"]["parameters"] is None
                else {}
            )
        ),
    output:
        deck=f"{APPLICATION_RUN}/in.chute_cooler",
        info=f"{APPLICATION_RUN}/case.json",
    log:
        f"{LOGS}/application/render.log",
    localrule: True
    conda:
        CONDA_ENV
    threads: 1
    resources:
        runtime=resource("analysis", "runtime", 10),
        mem_mb=resource("analysis", "mem_mb", 1000),
    script:
        "../../scripts/render_chute_cooler.py"


rule application_run:
    input:
        deck=f"{APPLICATION_RUN}/in.chute_cooler",
        info=f"{APPLICATION_RUN}/case.json",
    output:
        status=f"{APPLICATION_RUN}/status.json",
    log:
        f"{LOGS}/application/run.log",
    benchmark:
        f"{RESULTS}/benchmarks/application/chute_cooler.tsv"
    params:
        command=lambda wildcards: config["engine"]["command"],
    conda:
        CONDA_ENV
    threads: config["engine"]["threads"]
    resources:
        runtime=resource("dem_case", "runtime", 120),
        mem_mb=resource("dem_case", "mem_mb", 4000),
    script:
        "../../scripts/run_chute_cooler.py"


rule application_analyse:
    input:
        status=f"{APPLICATION_RUN}/status.json",
        info=f"{APPLICATION_RUN}/case.json",
    output:
        table=f"{APPLICATION}/segregation.csv",
        index=f"{APPLICATION}/segregation_index.json",
        series=f"{APPLICATION}/segregation_time_series.csv",
        steady=f"{APPLICATION}/steady_state.png",
    log:
        f"{LOGS}/application/analyse.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        runtime=resource("analysis", "runtime", 30),
        mem_mb=resource("analysis", "mem_mb", 4000),
    script:
        "../../scripts/analyse_chute_cooler.py"


rule application_figures:
    input:
        status=f"{APPLICATION_RUN}/status.json",
        info=f"{APPLICATION_RUN}/case.json",
        table=f"{APPLICATION}/segregation.csv",
    output:
        fig11=f"{APPLICATION}/fig11_segregation.png",
        fig10=f"{APPLICATION}/fig10_layout.png",
        vtk=directory(f"{APPLICATION}/vtk"),
    log:
        f"{LOGS}/application/figures.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        runtime=resource("plotting", "runtime", 30),
        mem_mb=resource("plotting", "mem_mb", 4000),
    script:
        "../../scripts/chute_cooler_figures.py"
