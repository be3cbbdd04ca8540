"""The bonded layer's truth for tests: a re-export of
:mod:`tactsense.analysis.layer_truth` (Love's strain function solved per wavenumber, the
load's exact Hankel transform; shares nothing with the simulator's FFT grid), under the
name the tests have used."""

from tactsense.analysis.layer_truth import hankel_hertz_strain, taxel_strain

__all__ = ["hankel_hertz_strain", "taxel_strain"]
