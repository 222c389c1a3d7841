"""The application: the analysis pipeline, runs, studies, comparisons and the command line."""
