# Stage 1: the design of DEM cases (one row per parameter set).


rule design_table:
    output:
        table=report(DESIGN_TABLE, category="Design", caption="../report/design.rst"),
    log:
        f"{LOGS}/design/design_table.log",
    params:
        section=config["design"],
    localrule: True
    conda:
        CONDA_ENV
    script:
        "../../scripts/write_design.py"
