"""Native (C99) FMUs of the crane models: one C file per model over one generic FMI 2.0 layer.

``include/cf_model.h`` is the contract a model file fulfils; :mod:`.tables` generates each model's
index header from the same signal and parameter tables as the pythonfmu FMU, so the two cannot drift.

Internal: no module here is public API (its face is ``cranefmu build``; docs/architecture.md).
"""
