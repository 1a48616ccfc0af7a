# Flat-bottom silo runs siloflow did not make (silo_flat.existing_runs): a user's own engine run, known from its
# particle dumps alone -> flow metrics, coarse-grained fields and profiles in results/existing_runs/silo_flat/<name>/.
# Each run's folder and dumps are checked when the workflow starts (siloflow.engines.preflight), before any step runs. The dump files are the
# rules' inputs (a changed dump reruns its run's analysis); the run's description reaches the scripts as data only.

from siloflow.engines.layout import existing_run_dir, existing_run_path

wildcard_constraints:
    existing="[A-Za-z0-9][A-Za-z0-9_.-]*",


#: Each configured run's dump files, by name (checked by siloflow.engines.preflight when the workflow is parsed).
EXISTING_SILO_DUMPS = PREFLIGHT.existing_dumps


def existing_dumps(wildcards):
    """The dump files of one run siloflow did not make."""
    return [str(dump.path) for dump in EXISTING_SILO_DUMPS[wildcards.existing]]


def existing_description(wildcards):
    """One run's entry of silo_flat.existing_runs (data: the script builds the description from it)."""
    return config["silo_flat"]["existing_runs"][wildcards.existing]


def existing_products():
    """Every product of the analysis of one run siloflow did not make, relative to its folder."""
    prefix = existing_run_dir("silo_flat") + "/"
    products = (*rules.existing_silo_metrics.output, *rules.existing_silo_fields.output)
    return [str(path)[len(prefix):] for path in products]


def existing_runs_targets(wildcards=None):
    """The products of every run of silo_flat.existing_runs (none by default)."""
    return [existing_run_path("silo_flat", name, run) for run in EXISTING_SILO_DUMPS for name in existing_products()]


rule existing_silo_metrics:
    input:
        dumps=existing_dumps,
    output:
        table=existing_run_path("silo_flat", "metrics/flow.csv"),
        history=existing_run_path("silo_flat", "metrics/discharge.csv"),
        summary=existing_run_path("silo_flat", "metrics/flow.json"),
        plot=existing_run_path("silo_flat", plot_file("plots/discharge")),
    params:
        run=existing_description,
        analysis=lambda wildcards: {
            "steady_window": config["silo_flat"]["steady_window"],
            "beverloo": config["silo_flat"]["beverloo"],
        },
        on_damaged=config["dumps"]["on_damaged"],
    log:
        existing_run_path("silo_flat", "logs/metrics.log"),
    script:
        "../scripts/existing_silo_metrics.py"


rule existing_silo_fields:
    input:
        dumps=existing_dumps,
        flow=rules.existing_silo_metrics.output.summary,
    output:
        pvd=existing_run_path("silo_flat", "fields/fields.pvd"),
        arrays=existing_run_path("silo_flat", "fields/averaged.npz"),
        profiles=existing_run_path("silo_flat", "metrics/profiles.csv"),
        instantaneous=existing_run_path("silo_flat", "metrics/profiles_instantaneous.csv"),
        boundaries=existing_run_path("silo_flat", "metrics/flow_channel_boundary.csv"),
        kinematic=existing_run_path("silo_flat", "metrics/kinematic.csv"),
        centreline=existing_run_path("silo_flat", "metrics/centreline_velocity.csv"),
        summary=existing_run_path("silo_flat", "metrics/fields.json"),
        analyses=existing_run_path("silo_flat", "metrics/analyses.json"),
        profile_plot=existing_run_path("silo_flat", plot_file("plots/profiles")),
        contour_plot=existing_run_path("silo_flat", plot_file("plots/vz_contour")),
        kinematic_plot=existing_run_path("silo_flat", plot_file("plots/kinematic_B")),
        kinematic_u_plot=existing_run_path("silo_flat", plot_file("plots/kinematic_u")),
        centreline_plot=existing_run_path("silo_flat", plot_file("plots/centreline_velocity")),
    params:
        run=existing_description,
        settings=lambda wildcards: config["silo_flat"]["fields"],
        made=lambda wildcards: existing_products(),
        on_damaged=config["dumps"]["on_damaged"],
    log:
        existing_run_path("silo_flat", "logs/fields.log"),
    script:
        "../scripts/existing_silo_fields.py"


rule existing_runs:
    input:
        existing_runs_targets,
