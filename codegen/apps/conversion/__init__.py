"""Records of one format into another (``battgen convert``) and the conformance vectors of a converter (``battgen
vectors``)."""
