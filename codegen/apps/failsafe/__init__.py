"""The battery failsafe: the evaluator, its levels in the messages, sample streams, parameter checks."""
