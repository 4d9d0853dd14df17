"""rti-rig: controller for Reflectance Transformation Imaging rigs."""

import time as _time

__version__ = "0.1.0"

#: When this process imported rti-rig (``time.time_ns()``). Why: a Dask worker keeps the code
#: it imported; a source file changed after this (an editable install edited, a checkout
#: switched) is not the code it runs, whatever its file now says. Asked by
#: :mod:`rti_rig.app.usecases.worker_code` only of a process that imported rti-rig before its
#: first check (later checks compare the files' contents with those of the first).
IMPORTED_AT_NS = _time.time_ns()
