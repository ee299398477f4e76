"""The sources of `scripts/regen-docs`: the runs that give the documents' figures."""
