"""The validation table: the study's comparisons as one table, each row judged against a finding of the study
(:mod:`~siloflow.analysis.studies.validation.findings`, :mod:`~siloflow.analysis.studies.validation.agreement`) and at
the study's scale or not (:mod:`~siloflow.analysis.studies.validation.scale`); the row itself is
:mod:`~siloflow.analysis.studies.validation.rows`.

- :mod:`~siloflow.analysis.studies.validation.calibration`: the Jenike calibration (C1-C7);
- :mod:`~siloflow.analysis.studies.validation.silo`: the flat-bottom silo and the front-wall friction series (S1-S6);
- :mod:`~siloflow.analysis.studies.validation.blending`: the recirculating silo (B1-B8);
- :mod:`~siloflow.analysis.studies.validation.blender`: the multi-flow blender (M1-M3) and its gravity series;
- :mod:`~siloflow.analysis.studies.validation.group_rows`: one group's rows from its products;
- :mod:`~siloflow.analysis.studies.validation.findings_summary`: each finding's status over the rows;
- :mod:`~siloflow.analysis.studies.validation.table`: all rows in order, and the report page's sections;
- :mod:`~siloflow.analysis.studies.validation.record`: the record kept in the repository, and its page.
"""
