"""The compiled fixed-step engine (single runs in :mod:`.run`, batches in :mod:`.batch`)."""
