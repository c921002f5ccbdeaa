"""The reference results ``hippomaze bench`` ships, one JSON file per agent variant (see :mod:`hippomaze.bench.references`)."""
