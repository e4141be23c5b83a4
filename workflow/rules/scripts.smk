rule run_script:
    input:
        script="specs/scripts/{script}.anim",
        needs=script_inputs,
        code=code_inputs("mosys.cli.animation", "mosys.animation.trajectory_file"),  # mosys run
    output:
        "results/trajectories/{script}.h5",
    log:
        "results/logs/scripts/{script}.log",
    benchmark:
        "results/benchmarks/scripts/{script}.tsv"
    params:
        controllers=lambda wildcards: f"results/controllers/{script_group(wildcards.script)}",
        dt=lambda wildcards: script_dt(wildcards.script),
    threads: 1
    priority: 2  # on the path to the script's plots: schedule first
    shell:
        "NUMBA_NUM_THREADS={threads} mosys run {input.script} --controllers {params.controllers}"
        " --dynamics-dir results/dynamics --dt {params.dt} -o {output} > {log} 2>&1"
