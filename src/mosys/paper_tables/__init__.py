"""The papers' tables, each from the result files the pipeline builds."""
