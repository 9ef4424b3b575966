"""Program induction: explore-compress. An order-1 Markov model over instructions (with
learned subroutines) guides a pruned depth-first search run on the VCC; compression
refits the model on what was found. See docs/search.md."""
