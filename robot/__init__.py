"""MuJoCo MJX arm that carries out concepts. Not built yet: see issue 6."""
