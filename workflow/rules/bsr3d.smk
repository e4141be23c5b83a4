# 3-D BSR figures (the 1995 paper's section 4): their searches run by bsr.smk's bsr_search (a
# search that continues another waits for its results); here their drawings (a filmstrip, a GIF
# and the figure at rest per motion, each search's seeds' learning curves, Figures 7 and 8) and
# the 3-D runs table.

rule bsr3d_motion_plots:
    input:
        results=bsr3d_motion_results,
        code=code_inputs("mosys.cli.plots", "mosys.plots.bsr3d", "mosys.plots.figure_at_rest"),  # mosys plot bsr3d
    output:
        filmstrip=report("results/plots/bsr3d/{motion}/filmstrip.png", caption="../report/bsr3d_filmstrip.rst", category="1995 paper — 3-D figures", subcategory="{motion}"),
        gif=report("results/plots/bsr3d/{motion}/motion.gif", caption="../report/bsr3d_gif.rst", category="1995 paper — 3-D figures", subcategory="{motion}"),
        rest=report("results/plots/bsr3d/{motion}/rest.png", caption="../report/bsr3d_rest.rst", category="1995 paper — 3-D figures", subcategory="{motion}"),
    log:
        "results/logs/plots/bsr3d/{motion}.log",
    benchmark:
        "results/benchmarks/plots/bsr3d/{motion}.tsv"
    params:
        view=bsr3d_view,  # config bsr3d.cameras
    threads: 1
    shell:
        "mosys plot bsr3d {input.results} --filmstrip {output.filmstrip} --gif {output.gif}"
        " --rest {output.rest}{params.view} > {log} 2>&1"


rule bsr3d_learning_kinds:
    input:
        time=bsr3d_results(config["bsr3d"]["kinds"]["time"]),
        sense=bsr3d_results(config["bsr3d"]["kinds"]["sense"]),
        code=code_inputs("mosys.cli.plots", "mosys.plots.bsr3d_learning"),  # mosys plot bsr3d-kinds
    output:
        report("results/plots/bsr3d/learning_kinds.png", caption="../report/bsr3d_kinds.rst", category="1995 paper — 3-D figures", subcategory="Figures 7 and 8"),
    log:
        "results/logs/plots/bsr3d/learning_kinds.log",
    benchmark:
        "results/benchmarks/plots/bsr3d/learning_kinds.tsv"
    threads: 1
    shell:
        "mosys plot bsr3d-kinds --time {input.time} --sense {input.sense} -o {output} > {log} 2>&1"


rule bsr3d_seeds:
    input:
        results=bsr3d_results(*variability_searches()),
        code=code_inputs("mosys.cli.plots", "mosys.plots.bsr3d_learning"),  # mosys plot bsr3d-seeds
    output:
        report("results/plots/bsr3d/seeds.png", caption="../report/bsr3d_seeds.rst", category="1995 paper — 3-D figures", subcategory="Figures 7 and 8"),
    log:
        "results/logs/plots/bsr3d/seeds.log",
    benchmark:
        "results/benchmarks/plots/bsr3d/seeds.tsv"
    threads: 1
    shell:
        "mosys plot bsr3d-seeds {input.results} -o {output} > {log} 2>&1"


rule bsr3d_search_learning:
    input:
        results=bsr_seed_results,
        code=code_inputs("mosys.cli.plots", "mosys.plots.bsr3d_learning"),  # mosys plot bsr3d-seeds
    output:
        report("results/plots/bsr3d/{name}/learning.png", caption="../report/bsr3d_learning.rst", category="1995 paper — 3-D figures", subcategory="{name}"),
    log:
        "results/logs/plots/bsr3d/{name}_learning.log",
    benchmark:
        "results/benchmarks/plots/bsr3d/{name}_learning.tsv"
    threads: 1
    shell:
        "mosys plot bsr3d-seeds {input.results} -o {output} > {log} 2>&1"


rule bsr3d_runs_table:
    input:
        results=lambda wildcards: bsr3d_results(),
        code=code_inputs("mosys.cli.paper_tables", "mosys.paper_tables.bsr3d"),  # bsr3d-table
    output:
        csv=report("results/tables/bsr3d_runs.csv", caption="../report/bsr3d_table.rst", category="1995 paper — 3-D figures", subcategory="tables"),
        md="results/tables/bsr3d_runs.md",
    log:
        "results/logs/tables/bsr3d_runs.log",
    benchmark:
        "results/benchmarks/tables/bsr3d_runs.tsv"
    threads: 1
    shell:
        "mosys bsr3d-table {input.results} --csv {output.csv} --md {output.md} > {log} 2>&1"


rule bsr3d_targets_table:
    input:
        results=lambda wildcards: bsr3d_results(),
        code=code_inputs("mosys.cli.paper_tables", "mosys.paper_tables.bsr3d_targets"),
    output:
        csv=report("results/tables/bsr3d_targets.csv", caption="../report/bsr3d_targets.rst", category="1995 paper — 3-D figures", subcategory="tables"),
        md="results/tables/bsr3d_targets.md",
    log:
        "results/logs/tables/bsr3d_targets.log",
    benchmark:
        "results/benchmarks/tables/bsr3d_targets.tsv"
    params:
        roles=bsr3d_target_roles,
    threads: 1
    shell:
        "mosys bsr3d-targets {input.results} {params.roles} --csv {output.csv} --md {output.md} > {log} 2>&1"
