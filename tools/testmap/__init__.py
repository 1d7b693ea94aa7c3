"""Cohort's Doom 3-format test map generator (standard library only, deterministic output)."""
