"""The engines the CLI drives, each returning typed results and printing nothing.

- :mod:`.validate`: data files against a message's generated validator;
- :mod:`.convert`: records between formats through the generated converters;
- :mod:`.failsafe`: the battery failsafe (evaluator, sample streams, parameter checks);
- :mod:`.batt_parameters`, :mod:`.batt_proposal`, :mod:`.ocv`: failsafe parameters from a devicetree battery;
- :mod:`.package`: where the generated package is (the one place that knows);
- :mod:`.messages`: a message of a schema by the names a user gives it.
"""
