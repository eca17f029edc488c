"""Jobs: what a user runs, built on the solver and the outputs (the main job: one case to its
end with every output written)."""
