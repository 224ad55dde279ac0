"""Measured data: the measurement file, ISO 9283 figures of it, frame registration, drift, dwells, noise floor.

Modules: :mod:`.contract` (reading the measurement file), :mod:`.registration`
(measuring frame -> world frame), :mod:`.figures` (per pose and direction),
:mod:`.drift` (dAP, dRP over time), :mod:`.segmentation` (dwells of a raw
stream), :mod:`.noise` (the instrument's own spread).
"""
