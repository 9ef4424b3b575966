"""Program induction (explore-compress over the JAX emulator). Not built yet: see issue 4."""
