"""Design questions: sensitivity against depth, spacing and materials."""

from tactsense.analysis.design import strip_capacitor_design

__all__ = ["strip_capacitor_design"]
