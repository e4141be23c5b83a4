# Luxo the lamp (1990 paper, section 7): the plots and the motions table of its show. Its
# dynamics, its landing controller and its trajectories come from the generic compile_dynamics,
# dp_controller and run_script rules (a script of Luxo's figure draws on the luxo group).

rule luxo_plots:
    input:
        trajectory="results/trajectories/{script}.h5",
        code=code_inputs("mosys.cli.plots", "mosys.plots.luxo"),  # mosys plot luxo
    output:
        strip=report("results/plots/luxo/{script}_strip.png", caption="../report/luxo_strip.rst", category="1990 paper — Luxo the lamp"),
        gif=report("results/plots/luxo/{script}.gif", caption="../report/luxo_gif.rst", category="1990 paper — Luxo the lamp"),
        forces=report("results/plots/luxo/{script}_forces.png", caption="../report/luxo_forces.rst", category="1990 paper — Luxo the lamp"),
    log:
        "results/logs/plots/luxo/{script}.log",
    benchmark:
        "results/benchmarks/plots/luxo/{script}.tsv"
    params:
        motion=luxo_strip_motion,
    threads: 1
    shell:
        "mosys plot luxo {input.trajectory} --strip {output.strip} {params.motion}"
        " --gif {output.gif} --forces {output.forces} > {log} 2>&1"


rule luxo_motions_table:
    input:
        trajectory=f"results/trajectories/{luxo_script()}.h5",
        landing=f"results/controllers/{config['luxo']['group']}/{config['luxo']['controller']}.h5",
        code=code_inputs("mosys.cli.paper_tables", "mosys.paper_tables.luxo"),  # mosys luxo-table
    output:
        csv=report("results/tables/luxo_motions.csv", caption="../report/luxo_table.rst", category="1990 paper — Luxo the lamp"),
        md="results/tables/luxo_motions.md",
    log:
        "results/logs/tables/luxo_motions.log",
    benchmark:
        "results/benchmarks/tables/luxo_motions.tsv"
    params:
        budget=config["budget"],
    threads: 1
    shell:
        "mosys luxo-table {input.trajectory} --landing {input.landing} --budget {params.budget}"
        " --csv {output.csv} --md {output.md} > {log} 2>&1"
