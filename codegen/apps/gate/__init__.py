"""The CI gate (``battgen validate``): the checks of data files and devicetree nodes, rule selection and firmware
profiles, and the findings written for people and CI systems."""
