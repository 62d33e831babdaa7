"""Backends: IR -> output. They only consume IR (:mod:`codegen.ir`); no backend imports another.

- :mod:`.python`: the generated Python package (``battgen generate``);
- :mod:`.json_schema`: JSON Schema (Draft 2020-12) of each message (``battgen schema``);
- :mod:`.markdown`: reference pages in PX4's message reference layout (``battgen docs``).
"""
