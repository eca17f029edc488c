"""Studies on top of the solver: verification against analytic solutions, the accuracy study,
the paper's cases, the robustness matrix, the speed benchmark and parameter sweeps."""
