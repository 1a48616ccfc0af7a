# The DEM verification suite: single-sphere problems with closed-form answers (siloflow.model.cases.verification), each run
# on every engine siloflow has, and one table of closed form, measured value, relative error and tolerance per
# engine (`snakemake verification`). Cheap: seconds per run. A row outside its tolerance is reported with its known reason;
# an unexplained one fails the table.

VERIFICATION_PROBLEMS = verification_cases()


def verification_targets():
    """The suite's table when the default target runs it (verification.enabled), else nothing."""
    return [f"{VERIFICATION_DIR}/verification.csv"] if config["verification"]["enabled"] else []


#: What each problem checks, for the report page.
VERIFICATION_EXPLANATIONS = {
    "wall_impact": "A sphere hits the floor at 1 m/s, elastically: it rebounds at its impact speed after the Hertz "
                   "contact time of a sphere on a flat (R* = r).",
    "wall_impact_damped": "The same at restitution 0.5: rebound over impact speed is the configured restitution.",
    "pair_impact": "Two spheres meet head-on at 0.5 m/s each, elastically: restitution 1 and the Hertz time of the "
                   "pair (R* = r/2, m* = m/2).",
    "pair_impact_damped": "The same at restitution 0.5.",
    "slide_to_roll": "A sphere slides at 0.2 m/s without spin (friction 0.35): it rolls from t* = 2 v0 / (7 mu g) on, "
                     "at 5/7 v0.",
    "rolling": "A sphere rolls at 0.05 m/s without slip (rolling friction 0.1): a constant directional torque "
               "slows it at (5/7) mu_r g; YADE's elastic-plastic rolling moment does the same once it is at its cap.",
    "incline_slide": "A block of four spheres on the floor, gravity tilted by 30 degrees (tan 30 > mu = 0.35): it "
                     "slides at g (sin 30 - mu cos 30).",
    "incline_stick": "The same block at 15 degrees (tan 15 < mu): friction holds it; the error is relative to "
                     "g sin 15.",
    "clump_rotation": "The two-sphere clump spins freely at 100 rad/s, 30 degrees off its long axis: the axis precesses "
                      "about the angular momentum L at |L| / I_perp, with the inertia of the union of the spheres.",
    "pair_spin": "A sphere held in place presses on a fixed sphere at an overlap of 0.002 r and spins at 50 rad/s "
                 "across the normal, without sliding friction: the study's rolling torque mu_r |Fn| r (mu_r = 0.1, "
                 "|Fn| Hertz's at the overlap) slows its spin at mu_r |Fn| r / I. The contact every clump makes; "
                 "LIGGGHTS' CDT gets the mapped coefficient 2 mu_r (docs/engines.md, The rolling law).",
    "wall_spin": "The same sphere on the floor: the wall's torque mu_r |Fn| r, with LIGGGHTS' coefficient mu_r.",
    "clump_pair_spin": "The two-sphere clump, held in place, lies on a fixed one, side by side and parallel, each "
                       "sphere pressing on the one below at an overlap of 0.002 r, and spins at 50 rad/s about its long "
                       "axis, across the normals, without sliding friction: the study's torque mu_r |Fn| R_i at each "
                       "contact (R_i = 1.545 mm from the contact point to the centre of mass) slows it at "
                       "sum mu_r |Fn| R_i / I. The engines' mapping gives each contact the torque at the clump's mean "
                       "lever arm R = 1.673 mm: torque_ratio is the measured deceleration over the study's, against "
                       "R / R_i (docs/engines.md, The rolling law).",
}

#: Rows that differ on an engine, and why ("<engine>/<problem>/<quantity>"): the report says it beside the row.
VERIFICATION_KNOWN_DIFFERENCES = {
    "yade/wall_impact/contact_time": "YADE's sphere-wall geometry (Ig2_Wall_Sphere_ScGeom) gives both radii as r, so "
    "Hertz-Mindlin takes R* = r/2 as for two spheres instead of r for a flat: a softer contact that lasts 2^(1/5) = "
    "1.149 times the flat's. Every sphere-wall contact on YADE is softer than on LIGGGHTS in the same way.",
    "yade/wall_spin/spin_deceleration": "YADE's sphere-wall geometry takes R* = r/2 (see wall_impact): at the same "
    "overlap its normal force is 2^(-1/2) = 0.707 of a flat's, and the rolling moment, capped at eta r |Fn| as on a "
    "pair, with it.",
    "liggghts/clump_pair_spin/spin_deceleration": "The mapping's: LIGGGHTS' CDT is given the study's torque at the "
    "clump's mean lever arm R = 1.673 mm, this contact's own is R_i = 1.545 mm, so the spin slows at R / R_i = 1.083 "
    "times the study's (the torque_ratio row checks that it does).",
    "yade/clump_pair_spin/spin_deceleration": "The mapping's: YADE's eta gives the study's torque at the clump's mean "
    "lever arm R = 1.673 mm, this contact's own is R_i = 1.545 mm, so the spin slows at R / R_i = 1.083 times the "
    "study's (the torque_ratio row checks that it does).",
}


rule verification_run:
    output:
        record=f"{VERIFICATION_DIR}/{{engine}}/{{problem}}/{RUN_RECORD}",
    params:
        problem=lambda wildcards: wildcards.problem,
    wildcard_constraints:
        engine="|".join(ENGINE_KINDS),
        problem="|".join(VERIFICATION_PROBLEMS),
    log:
        f"{VERIFICATION_DIR}/{{engine}}/{{problem}}/logs/run.log",
    script:
        "../scripts/verification_run.py"


rule verification_table:
    input:
        records=expand(f"{VERIFICATION_DIR}/{{engine}}/{{problem}}/{RUN_RECORD}", engine=ENGINE_KINDS,
                       problem=VERIFICATION_PROBLEMS),
    output:
        table=f"{VERIFICATION_DIR}/verification.csv",
        page=report(f"{VERIFICATION_DIR}/verification.html", caption="../report/verification.rst",
                    category="0 Summary", labels={"figure": "verification table"}),
    params:
        explanation=VERIFICATION_EXPLANATIONS,
        known_differences=VERIFICATION_KNOWN_DIFFERENCES,
    log:
        f"{VERIFICATION_DIR}/logs/verification_table.log",
    script:
        "../scripts/verification_table.py"


rule verification:
    input:
        rules.verification_table.output.table,
