"""Drawings: ``style`` is the one base every plot family shares."""
