"""Where examples come from: the 546 concepts and their reference programs, random
scenes and programs, example pairs that pin a concept down (against rival programs),
and datasets of them, with the data shipped in `data/`."""
