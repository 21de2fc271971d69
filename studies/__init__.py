"""What connects the layers: FEM studies, comparisons, the batch runner and the CLI.

Its public face, imported on first use: the studies (:mod:`~softhand.studies.bending`,
:mod:`~softhand.studies.reservoir`, :mod:`~softhand.studies.weights`, each a parameter class
and a ``run``) and the batch runner (:func:`~softhand.studies.batch.studyfile.study_from_dict`, :func:`~softhand.studies.batch.runner.run_study`,
:func:`~softhand.studies.batch.index.index_rows`).
"""
if __name__ != "softhand.studies":  # the folder on sys.path, imported by its short name
    raise ImportError(f"'{__name__}' is softhand.studies: import softhand.studies (after pip install -e .)")

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
