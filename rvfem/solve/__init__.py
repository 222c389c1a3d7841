"""The solve: contacts, bearing and pin models, one crank angle and the load cycle of a stage."""
