"""Plan-level priors applied after the majority vote, in one chain (``chain.apply_priors``)."""
