"""Argument prediction CNN (flax/optax). Not built yet: see issue 5."""
