"""Looking at runs: per-instruction traces of the reference machine, the trace viewer
(PNG, GIF), and text pictures of scenes for the terminal."""
