"""Evaluation of the loads: the rigid handbook, Hertz, ISO 281, comparisons, stresses."""
