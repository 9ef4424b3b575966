"""Argument prediction: a flax CNN, trained with optax on drawn short programs, that
reads a concept's example pairs and says which arguments `set_shape_attn`,
`set_color_attn` and `fill_color` take (paper, "Argument prediction")."""
