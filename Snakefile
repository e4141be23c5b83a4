# mosys: the pipeline. Targets are plain paths under results/, e.g.
#   snakemake results/pendulum_all     (profiles/default sets the cores)
configfile: "config/config.yaml"


# Every wildcard is a name (a letter or _, then letters, digits or _), a seed a whole number:
# a mistyped target (a slash or dot in the wrong place) matches no rule instead of a wrong one.
wildcard_constraints:
    group=r"[A-Za-z_]\w*",
    name=r"[A-Za-z_]\w*",
    script=r"[A-Za-z_]\w*",
    figure=r"[A-Za-z_]\w*",
    motion=r"[A-Za-z_]\w*",
    seed=r"\d+",


report: "workflow/report/workflow.rst"


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


# The aggregate targets only write an index of their inputs: on a cluster they run where
# Snakemake runs, not as SLURM jobs.
localrules:
    all,
    pendulum_all,
    car_all,
    luxo_all,
    bsr_all,
    bsr3d_all,
    composite_all,
    paper_tables,


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
        lambda wildcards: pendulum_targets(),
    output:
        "results/pendulum_all",
    log:
        "results/logs/pendulum_all.log",
    shell:
        "mosys index {input} -o {output} > {log} 2>&1"


rule car_all:
    input:
        lambda wildcards: car_targets(),
    output:
        "results/car_all",
    log:
        "results/logs/car_all.log",
    shell:
        "mosys index {input} -o {output} > {log} 2>&1"


rule luxo_all:
    input:
        lambda wildcards: luxo_targets(),
    output:
        "results/luxo_all",
    log:
        "results/logs/luxo_all.log",
    shell:
        "mosys index {input} -o {output} > {log} 2>&1"


rule bsr_all:
    input:
        lambda wildcards: bsr_targets(),
    output:
        "results/bsr_all",
    log:
        "results/logs/bsr_all.log",
    shell:
        "mosys index {input} -o {output} > {log} 2>&1"


rule bsr3d_all:
    input:
        lambda wildcards: bsr3d_targets(),
    output:
        "results/bsr3d_all",
    log:
        "results/logs/bsr3d_all.log",
    shell:
        "mosys index {input} -o {output} > {log} 2>&1"


rule composite_all:
    input:
        lambda wildcards: composite_targets(),
    output:
        "results/composite_all",
    log:
        "results/logs/composite_all.log",
    shell:
        "mosys index {input} -o {output} > {log} 2>&1"


rule paper_tables:
    input:
        lambda wildcards: paper_table_targets() + car_table_targets() + luxo_table_targets()
        + bsr_table_targets() + bsr3d_table_targets() + composite_table_targets(),
    output:
        "results/paper_tables",
    log:
        "results/logs/paper_tables.log",
    shell:
        "mosys index {input} -o {output} > {log} 2>&1"
