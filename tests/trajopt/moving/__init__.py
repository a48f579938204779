"""Tests of trajopt.moving."""
