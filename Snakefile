# mosys: the pipeline. Targets are plain paths under results/, e.g.
#   snakemake results/pendulum_all     (profiles/default sets the cores)
configfile: "config/config.yaml"


include: "workflow/rules/common.smk"
include: "workflow/rules/dynamics.smk"
include: "workflow/rules/ssc.smk"
include: "workflow/rules/scripts.smk"
include: "workflow/rules/plots.smk"
include: "workflow/rules/tables.smk"
include: "workflow/rules/car.smk"
include: "workflow/rules/luxo.smk"
include: "workflow/rules/bsr.smk"
include: "workflow/rules/bsr3d.smk"
include: "workflow/rules/composite.smk"


rule all:
    input:
        "results/pendulum_all",
        "results/car_all",
        "results/luxo_all",
        "results/bsr_all",
        "results/bsr3d_all",
        "results/composite_all",
        "results/paper_tables",


rule pendulum_all:
    input:
        pendulum_targets(),
    output:
        "results/pendulum_all",
    log:
        "results/logs/pendulum_all.log",
    shell:
        "mosys index {input} -o {output} 2> {log}"


rule car_all:
    input:
        car_targets(),
    output:
        "results/car_all",
    log:
        "results/logs/car_all.log",
    shell:
        "mosys index {input} -o {output} 2> {log}"


rule luxo_all:
    input:
        luxo_targets(),
    output:
        "results/luxo_all",
    log:
        "results/logs/luxo_all.log",
    shell:
        "mosys index {input} -o {output} 2> {log}"


rule bsr_all:
    input:
        bsr_targets(),
    output:
        "results/bsr_all",
    log:
        "results/logs/bsr_all.log",
    shell:
        "mosys index {input} -o {output} 2> {log}"


rule bsr3d_all:
    input:
        bsr3d_targets(),
    output:
        "results/bsr3d_all",
    log:
        "results/logs/bsr3d_all.log",
    shell:
        "mosys index {input} -o {output} 2> {log}"


rule composite_all:
    input:
        composite_targets(),
    output:
        "results/composite_all",
    log:
        "results/logs/composite_all.log",
    shell:
        "mosys index {input} -o {output} 2> {log}"


rule paper_tables:
    input:
        paper_table_targets() + car_table_targets() + luxo_table_targets()
        + bsr_table_targets() + bsr3d_table_targets() + composite_table_targets(),
    output:
        "results/paper_tables",
    log:
        "results/logs/paper_tables.log",
    shell:
        "mosys index {input} -o {output} 2> {log}"
