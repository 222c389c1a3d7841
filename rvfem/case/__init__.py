"""The case: its schema, its tables and the registries of the models it names."""
