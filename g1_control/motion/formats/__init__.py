"""Readers and writers of motion files; `formats.load` picks one by file extension."""
