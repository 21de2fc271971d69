"""Shared by every test folder: the CI mesh presets, named once.

The tests mirror the code (``tests/fem``, ``tests/reduced``, ``tests/meshes``, ``tests/studies``;
``tests/project`` for what spans them). This folder is on ``sys.path`` while they run, so the
helper modules beside this file (``bad_input_cases``) import by their plain names.
"""
