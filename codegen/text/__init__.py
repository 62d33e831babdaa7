"""Reading input text, shared by the frontends and the data readers.

- :mod:`.files`: read a file as UTF-8 (errors name file and line) and the path IR locations show.
- :mod:`.yaml_lines`: safe YAML loading that remembers the line of every mapping and sequence.
- :mod:`.xml`: the one hardened expat set-up (no DTDs, no entities) for XML schema files.
"""
