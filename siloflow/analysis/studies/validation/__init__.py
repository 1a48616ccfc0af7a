"""The validation table: the study's comparisons as one table, each row with its uncertainty and whether the
scale of its runs shows the physics it is about (:mod:`siloflow.analysis.studies.validation.rows`).

- :mod:`~siloflow.analysis.studies.validation.calibration`: bulk-friction curves and the checks around them;
- :mod:`~siloflow.analysis.studies.validation.silo`: the flat-bottom silo and the front-wall friction series;
- :mod:`~siloflow.analysis.studies.validation.blending`: the recirculating silo and the blender;
- :mod:`~siloflow.analysis.studies.validation.table`: all rows in order, and the report page's sections.
"""
