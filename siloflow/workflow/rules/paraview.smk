# ParaView files of every run of the silo-type kinds (paraview.enabled): under each run's paraview/, the particle frames
# on the simulated clock (particles.pvd), the walls, the settled fill's force chains, the kind's fields and lines, and
# a ParaView state (state.py) that opens them all. Each run's state (which needs the others) joins its kind's
# CASE_TARGETS, so `rule all` and the validation groups build the ParaView files with the rest of its runs'.

#: Per case kind with ParaView files: the lines its runs add (tracks of the recirculating silo's clumps cut into
#: passes, the blender's pathlines); every such kind also has particles, walls, force chains and fields. The one place
#: per kind; its fields rule is below.
PARAVIEW_LINES = {"silo_flat": (), RECIRCULATION: ("tracks",), "blender": ("pathlines",)}

#: The files of a run's ParaView folder every kind has besides its state (which names them and the kind's lines).
PARAVIEW_COMMON = ("particles.pvd", "walls.vtp", "force_chains.vtp", "fields.pvd")


def paraview_path(kind, name):
    """A file of the ParaView folder of a run of ``kind`` (``{run}`` wildcard)."""
    return run_path(kind, f"paraview/{name}")


def paraview_targets(kind, runs=None):
    """The ParaView state of each run of ``kind`` (``runs``: of these run ids; all when None), which needs every other
    ParaView file of its run, so asking for it builds them all (and `make run` prints one line per run, the file to
    open); none when paraview.enabled is off."""
    if not config["paraview"]["enabled"] or kind not in PARAVIEW_LINES:
        return []
    return [run_path(kind, "paraview/state.py", run) for run in among(run_ids(kind), runs)]


def with_paraview(kind, targets):
    """The products ``targets(wildcards, runs)`` of a kind with its ParaView files."""
    def products(wildcards=None, runs=None):
        return [*targets(wildcards, runs=runs), *paraview_targets(kind, runs)]
    return products


def paraview_state_title(kind):
    """What the state of a run of ``kind`` says it opens: kind, run id and engine."""
    def title(wildcards):
        return f"{kind} run {wildcards.run} ({engine_kind(config, kind)})"
    return title


for _kind in PARAVIEW_LINES:
    CASE_TARGETS[_kind] = with_paraview(_kind, CASE_TARGETS[_kind])

    rule:
        name:
            f"{_kind}_paraview_particles"
        input:
            record=run_rule_output(_kind),
        output:
            pvd=paraview_path(_kind, "particles.pvd"),
        params:
            on_damaged=config["dumps"]["on_damaged"],
        log:
            run_path(_kind, "logs/paraview_particles.log"),
        script:
            "../scripts/paraview_particles.py"

    rule:
        name:
            f"{_kind}_paraview_walls"
        input:
            case=deck_rule_output(_kind),
        output:
            walls=paraview_path(_kind, "walls.vtp"),
        params:
            kind=_kind,
            case=typed_case(_kind),
        log:
            run_path(_kind, "logs/paraview_walls.log"),
        script:
            "../scripts/paraview_walls.py"

    rule:
        name:
            f"{_kind}_paraview_force_chains"
        input:
            # the settled fill's run: a run that starts from another run's settled fill shows that one's chains
            record=settled_fill_record(_kind),
        output:
            chains=paraview_path(_kind, "force_chains.vtp"),
        log:
            run_path(_kind, "logs/paraview_force_chains.log"),
        script:
            "../scripts/paraview_force_chains.py"

    rule:
        name:
            f"{_kind}_paraview_state"
        input:
            **{name.split(".")[0]: paraview_path(_kind, name) for name in PARAVIEW_COMMON},
            **{line: paraview_path(_kind, f"{line}.vtp") for line in PARAVIEW_LINES[_kind]},
        output:
            state=paraview_path(_kind, "state.py"),
        params:
            title=paraview_state_title(_kind),
        log:
            run_path(_kind, "logs/paraview_state.log"),
        script:
            "../scripts/paraview_state.py"


# The fields of each kind, on the simulated clock of its particles.


rule silo_flat_paraview_fields:
    input:
        record=run_rule_output("silo_flat"),
        fields=rules.silo_fields.output.pvd,
        particles=paraview_path("silo_flat", "particles.pvd"),
    output:
        pvd=paraview_path("silo_flat", "fields.pvd"),
    log:
        run_path("silo_flat", "logs/paraview_fields.log"),
    script:
        "../scripts/paraview_silo_fields.py"


rule silo_recirculation_paraview_fields:
    input:
        tracks=rules.silo_recirculation_tracks.output.tracks,
    output:
        pvd=paraview_path(RECIRCULATION, "fields.pvd"),
    params:
        case=typed_case(RECIRCULATION),
        bin_size=config[RECIRCULATION]["eulerian"]["bin_size"],
    log:
        run_path(RECIRCULATION, "logs/paraview_fields.log"),
    script:
        "../scripts/paraview_recirculation_fields.py"


rule silo_recirculation_paraview_tracks:
    input:
        tracks=rules.silo_recirculation_tracks.output.tracks,
    output:
        tracks=paraview_path(RECIRCULATION, "tracks.vtp"),
    params:
        case=typed_case(RECIRCULATION),
    log:
        run_path(RECIRCULATION, "logs/paraview_tracks.log"),
    script:
        "../scripts/paraview_tracks.py"


rule blender_paraview_fields:
    input:
        record=run_rule_output("blender"),
        frames=rules.blender_fields.output.frames,
    output:
        pvd=paraview_path("blender", "fields.pvd"),
    params:
        case=typed_case("blender"),
    log:
        run_path("blender", "logs/paraview_fields.log"),
    script:
        "../scripts/paraview_blender_fields.py"


rule blender_paraview_pathlines:
    input:
        fields=rules.blender_fields.output.fields,
    output:
        pathlines=paraview_path("blender", "pathlines.vtp"),
    params:
        case=typed_case("blender"),
        pathlines=config["blender"]["pathlines"],
    log:
        run_path("blender", "logs/paraview_pathlines.log"),
    script:
        "../scripts/paraview_pathlines.py"
