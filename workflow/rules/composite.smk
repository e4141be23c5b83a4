# Composite motion (the 1995 paper's section 3): a script's transition-point search over the
# robust BSR controllers its phases name, the plots of the motion before and after, the
# composite table and the robustness table of the enhanced controllers.

rule composite_search:
    input:
        unpack(composite_inputs),
        code=code_inputs(
            "mosys.cli.composite",
            "mosys.composite.result_file",
            "mosys.composite.session",
            "mosys.parsing.composite",
        ),  # mosys composite
    output:
        "results/composite/{name}.h5",
    log:
        "results/logs/composite/{name}.log",
    benchmark:
        "results/benchmarks/composite/{name}.tsv"
    params:
        sizes=composite_search_options,
        budget=config["budget"],
    threads: 1
    shell:
        "mosys composite {input.script} --controllers {input.controllers}"
        " --figures specs/figures --bsr-specs specs/bsr {params.sizes}"
        " --budget {params.budget} -o {output} > {log} 2>&1"


rule composite_plots:
    input:
        result="results/composite/{name}.h5",
        code=code_inputs("mosys.cli.plots", "mosys.plots.composite"),  # mosys plot composite
    output:
        filmstrips=report("results/plots/composite/{name}/filmstrips.png", caption="../report/composite_filmstrips.rst", category="1995 paper — composite motion", subcategory="{name}"),
        search=report("results/plots/composite/{name}/search.png", caption="../report/composite_search.rst", category="1995 paper — composite motion", subcategory="{name}"),
        gif=report("results/plots/composite/{name}/motion.gif", caption="../report/composite_gif.rst", category="1995 paper — composite motion", subcategory="{name}"),
    log:
        "results/logs/plots/composite/{name}.log",
    benchmark:
        "results/benchmarks/plots/composite/{name}.tsv"
    threads: 1
    shell:
        "mosys plot composite {input.result} --filmstrips {output.filmstrips}"
        " --search {output.search} --gif {output.gif} > {log} 2>&1"


rule composite_table:
    input:
        results=expand("results/composite/{name}.h5", name=config["composite"]["scripts"]),
        code=code_inputs("mosys.cli.paper_tables", "mosys.paper_tables.composite"),  # mosys composite-table
    output:
        csv=report("results/tables/composite.csv", caption="../report/composite_table.rst", category="1995 paper — composite motion", subcategory="tables"),
        md="results/tables/composite.md",
    log:
        "results/logs/tables/composite.log",
    benchmark:
        "results/benchmarks/tables/composite.tsv"
    threads: 1
    shell:
        "mosys composite-table {input.results} --csv {output.csv} --md {output.md} > {log} 2>&1"


rule composite_robustness_table:
    input:
        results=lambda wildcards: robustness_results(),
        specs=[f"specs/bsr/{search}.bsr" for pair in robustness_pairs() for search in pair],
        code=code_inputs("mosys.cli.paper_tables", "mosys.paper_tables.robustness"),  # mosys robustness-table
    output:
        csv=report("results/tables/composite_robustness.csv", caption="../report/robustness_table.rst", category="1995 paper — composite motion", subcategory="tables"),
        md="results/tables/composite_robustness.md",
    log:
        "results/logs/tables/composite_robustness.log",
    benchmark:
        "results/benchmarks/tables/composite_robustness.tsv"
    params:
        pairs=" ".join(f"--pair {robust} {plain}" for robust, plain in robustness_pairs()),
    threads: 1
    shell:
        "mosys robustness-table {input.results} {params.pairs} --bsr-specs specs/bsr"
        " --figures specs/figures --csv {output.csv} --md {output.md} > {log} 2>&1"
