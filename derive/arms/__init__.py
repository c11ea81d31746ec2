"""Bundled arm specs (package data)."""
