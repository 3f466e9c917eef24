"""Tests of the ballast harness (pytest); they use fake outputs and a fake core, never bin/ballast."""
