"""The paper's finger pipeline (Fearing 1990): from one finger's frames to its one contact.

Deflection from counts (eq. 4), the sinc interpolation of the surface (eq. 48) and
Newton's peak, force from the integral (eq. 55), the angle from the skew, the model fit
of the layer, the calibration of a finger and the frame-by-frame locator. Contacts on any
array (several per frame) are :mod:`tactsense.estimate.contacts`.
"""
