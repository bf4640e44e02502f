# Stage 1: the design of DEM cases (one row per case; ids, not floats, name the cases).


rule design_table:
    output:
        table=DESIGN_TABLE,
    log:
        f"{LOGS}/design/design_table.log",
    params:
        spec=config["design"],
    localrule: True
    conda:
        CONDA_ENV
    script:
        "../../scripts/write_design.py"
