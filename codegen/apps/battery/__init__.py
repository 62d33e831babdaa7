"""The battery-data layer: every log of every kind read once into batches of source columns with the log's
context, and turned into the shared battery concepts by the IR's mappings over whole columns (the battery view).
``export``, ``report`` and ``failsafe`` all read through it."""
