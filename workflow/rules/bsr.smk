# BSR controllers (the 1995 paper's section 2): one search job per (spec, seed), its plots, the
# comparison of learning curves and the runs table.

rule bsr_search:
    input:
        spec="specs/bsr/{name}.bsr",
        figure=bsr_figure_spec,
        chain=bsr_chain_results,
        code=code_inputs("mosys.cli.bsr", "mosys.bsr.result_file"),  # mosys bsr-search
    output:
        "results/bsr/{name}/seed{seed}.h5",
    log:
        "results/logs/bsr/{name}/seed{seed}.log",
    benchmark:
        "results/benchmarks/bsr/{name}/seed{seed}.tsv"
    params:
        generations=bsr_generations_option,
        budget=bsr_budget,
        chain=bsr_chain_option,
    threads: config["bsr"]["threads"]
    shell:
        "mosys bsr-search {input.spec} --seed {wildcards.seed} --figures specs/figures"
        " {params.generations} --budget {params.budget} {params.chain} --threads {threads}"
        " -o {output} > {log} 2>&1"


rule bsr_plots:
    input:
        results=bsr_seed_results,
        code=code_inputs("mosys.cli.plots", "mosys.plots.bsr", "mosys.plots.bsr_learning"),  # mosys plot bsr
    output:
        learning=report("results/plots/bsr/{name}/learning.png", caption="../report/bsr_learning.rst", category="1995 paper — BSR controllers (2-D)", subcategory="{name}"),
        filmstrip=report("results/plots/bsr/{name}/filmstrip.png", caption="../report/bsr_filmstrip.rst", category="1995 paper — BSR controllers (2-D)", subcategory="{name}"),
        gif=report("results/plots/bsr/{name}/motion.gif", caption="../report/bsr_gif.rst", category="1995 paper — BSR controllers (2-D)", subcategory="{name}"),
    log:
        "results/logs/plots/bsr/{name}.log",
    benchmark:
        "results/benchmarks/plots/bsr/{name}.tsv"
    threads: 1
    shell:
        "mosys plot bsr {input.results} --learning {output.learning}"
        " --filmstrip {output.filmstrip} --gif {output.gif} > {log} 2>&1"


rule bsr_learning_curves:
    input:
        results=lambda wildcards: bsr_all_results(),
        code=code_inputs("mosys.cli.plots", "mosys.plots.bsr_learning"),  # mosys plot bsr-learning
    output:
        report("results/plots/bsr/learning_curves.png", caption="../report/bsr_curves.rst", category="1995 paper — BSR controllers (2-D)", subcategory="all searches"),
    log:
        "results/logs/plots/bsr/learning_curves.log",
    benchmark:
        "results/benchmarks/plots/bsr/learning_curves.tsv"
    threads: 1
    shell:
        "mosys plot bsr-learning {input.results} -o {output} > {log} 2>&1"


rule bsr_runs_table:
    input:
        results=lambda wildcards: bsr_all_results(),
        code=code_inputs("mosys.cli.paper_tables", "mosys.paper_tables.bsr"),  # mosys bsr-table
    output:
        csv=report("results/tables/bsr_runs.csv", caption="../report/bsr_table.rst", category="1995 paper — BSR controllers (2-D)", subcategory="all searches"),
        md="results/tables/bsr_runs.md",
    log:
        "results/logs/tables/bsr_runs.log",
    benchmark:
        "results/benchmarks/tables/bsr_runs.tsv"
    threads: 1
    shell:
        "mosys bsr-table {input.results} --csv {output.csv} --md {output.md} > {log} 2>&1"
