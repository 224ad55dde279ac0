"""Measured data against the model: a measurement file's ISO 9283 figures (:func:`~tribokin.measured.iso_figures.
measure`) and a study's joint model fitted to it (:func:`~tribokin.measured.calibrated.calibrate`), each a frozen
result that writes its command's folder. Above ``run``: a calibration runs the calibrated study's map."""
