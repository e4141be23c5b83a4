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
        " -o {output}"
        " 2> {log} || (cat {log} >&2; exit 1)"


rule bsr_plots:
    input:
        results=bsr_seed_results,
        code=code_inputs("mosys.cli.plots", "mosys.plots.bsr"),  # mosys plot bsr
    output:
        learning="results/plots/bsr/{name}/learning.png",
        filmstrip="results/plots/bsr/{name}/filmstrip.png",
        gif="results/plots/bsr/{name}/motion.gif",
    log:
        "results/logs/plots/bsr/{name}.log",
    threads: 1
    shell:
        "mosys plot bsr {input.results} --learning {output.learning}"
        " --filmstrip {output.filmstrip} --gif {output.gif} 2> {log} || (cat {log} >&2; exit 1)"


rule bsr_learning_curves:
    input:
        results=bsr_all_results(),
        code=code_inputs("mosys.cli.plots", "mosys.plots.bsr"),  # mosys plot bsr-learning
    output:
        "results/plots/bsr/learning_curves.png",
    log:
        "results/logs/plots/bsr/learning_curves.log",
    threads: 1
    shell:
        "mosys plot bsr-learning {input.results} -o {output} 2> {log} || (cat {log} >&2; exit 1)"


rule bsr_runs_table:
    input:
        results=bsr_all_results(),
        code=code_inputs("mosys.cli.paper_tables", "mosys.paper_tables.bsr"),  # mosys bsr-table
    output:
        csv="results/tables/bsr_runs.csv",
        md="results/tables/bsr_runs.md",
    log:
        "results/logs/tables/bsr_runs.log",
    threads: 1
    shell:
        "mosys bsr-table {input.results} --csv {output.csv} --md {output.md}"
        " 2> {log} || (cat {log} >&2; exit 1)"
