"""The VCC machine: its instructions and programs, scenes, and two interpreters that
agree bit for bit: the batched JAX machine (`state`, `ops`, `step`, `motion`,
`match`) and the scalar reference (`reference`). Imports only numpy, jax and flax.
The specification is docs/vcc.md."""
