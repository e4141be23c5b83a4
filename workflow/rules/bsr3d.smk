# 3-D BSR figures (the 1995 paper's section 4): their searches run by bsr.smk's bsr_search (a
# search that continues another waits for its results); here their drawings (a filmstrip, a GIF
# and the figure at rest per motion, Figures 7 and 8) and the 3-D runs table.

wildcard_constraints:
    motion=r"\w+",


rule bsr3d_motion_plots:
    input:
        results=bsr3d_motion_results,
        code=code_inputs("mosys.cli.plots", "mosys.plots.bsr3d"),  # mosys plot bsr3d
    output:
        filmstrip="results/plots/bsr3d/{motion}/filmstrip.png",
        gif="results/plots/bsr3d/{motion}/motion.gif",
        rest="results/plots/bsr3d/{motion}/rest.png",
    log:
        "results/logs/plots/bsr3d/{motion}.log",
    threads: 1
    shell:
        "mosys plot bsr3d {input.results} --filmstrip {output.filmstrip} --gif {output.gif}"
        " --rest {output.rest} 2> {log} || (cat {log} >&2; exit 1)"


rule bsr3d_learning_kinds:
    input:
        time=bsr3d_results(config["bsr3d"]["kinds"]["time"]),
        sense=bsr3d_results(config["bsr3d"]["kinds"]["sense"]),
        code=code_inputs("mosys.cli.plots", "mosys.plots.bsr3d"),  # mosys plot bsr3d-kinds
    output:
        "results/plots/bsr3d/learning_kinds.png",
    log:
        "results/logs/plots/bsr3d/learning_kinds.log",
    threads: 1
    shell:
        "mosys plot bsr3d-kinds --time {input.time} --sense {input.sense} -o {output}"
        " 2> {log} || (cat {log} >&2; exit 1)"


rule bsr3d_seeds:
    input:
        results=bsr3d_results(config["bsr3d"]["variability"]),
        code=code_inputs("mosys.cli.plots", "mosys.plots.bsr3d"),  # mosys plot bsr3d-seeds
    output:
        "results/plots/bsr3d/seeds.png",
    log:
        "results/logs/plots/bsr3d/seeds.log",
    threads: 1
    shell:
        "mosys plot bsr3d-seeds {input.results} -o {output} 2> {log} || (cat {log} >&2; exit 1)"


rule bsr3d_runs_table:
    input:
        results=bsr3d_results(),
        code=code_inputs("mosys.cli.paper_tables", "mosys.paper_tables.bsr3d"),  # bsr3d-table
    output:
        csv="results/tables/bsr3d_runs.csv",
        md="results/tables/bsr3d_runs.md",
    log:
        "results/logs/tables/bsr3d_runs.log",
    threads: 1
    shell:
        "mosys bsr3d-table {input.results} --csv {output.csv} --md {output.md}"
        " 2> {log} || (cat {log} >&2; exit 1)"


rule bsr3d_targets_table:
    input:
        results=bsr3d_results(),
        code=code_inputs("mosys.cli.paper_tables", "mosys.paper_tables.bsr3d_targets"),
    output:
        csv="results/tables/bsr3d_targets.csv",
        md="results/tables/bsr3d_targets.md",
    log:
        "results/logs/tables/bsr3d_targets.log",
    params:
        roles=bsr3d_target_roles,
    threads: 1
    shell:
        "mosys bsr3d-targets {input.results} {params.roles} --csv {output.csv} --md {output.md}"
        " 2> {log} || (cat {log} >&2; exit 1)"
