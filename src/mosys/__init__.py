"""mosys: motion synthesis with state-space controllers (van de Panne et al. 1990) and BSR
controllers (Auslander et al. 1995)."""

__version__ = "0.1.0"
