"""Perception: a drawing in, labelled instances (a ``ParsedPlan``) out."""
