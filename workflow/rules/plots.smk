rule portrait_plot:
    input:
        table="results/controllers/{group}/{name}.h5",
        dynamics=lambda wildcards: f"results/dynamics/{config['pendulum']['figure']}.py",
        code=package_sources("ssc", "scripts", "plots"),
    output:
        "results/plots/{group}/{name}_portrait.png",
    log:
        "results/logs/plots/{group}/{name}_portrait.log",
    shell:
        "mosys plot portrait {input.table} --dynamics {input.dynamics} -o {output} 2> {log}"
        " || (cat {log} >&2; exit 1)"


rule torque_plot:
    input:
        table="results/controllers/{group}/{name}.h5",
        code=package_sources("plots"),
    output:
        "results/plots/{group}/{name}_torque.png",
    log:
        "results/logs/plots/{group}/{name}_torque.log",
    shell:
        "mosys plot torque {input.table} -o {output} 2> {log} || (cat {log} >&2; exit 1)"


rule script_path_plot:
    input:
        trajectory="results/trajectories/{script}.h5",
        tables=lambda wildcards: [p for p in script_inputs(wildcards) if p.endswith(".h5")],
        code=package_sources("plots"),
    output:
        "results/plots/{group}/{script}_path.png",
    log:
        "results/logs/plots/{group}/{script}_path.log",
    shell:
        "mosys plot script {input.trajectory} {input.tables} -o {output} 2> {log}"
        " || (cat {log} >&2; exit 1)"


rule script_animation:
    input:
        trajectory="results/trajectories/{script}.h5",
        code=package_sources("plots"),
    output:
        "results/plots/{group}/{script}.gif",
    log:
        "results/logs/plots/{group}/{script}_gif.log",
    shell:
        "mosys plot gif {input.trajectory} -o {output} 2> {log} || (cat {log} >&2; exit 1)"
