"""Drake LeafSystems and the navigation Diagram (installed as f2n_drake.systems)."""
