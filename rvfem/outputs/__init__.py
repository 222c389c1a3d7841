"""Outputs: summary, tables, VTK files, plots, images and the report."""
