"""Many videos: ``wallcli scan``.

One task = one video through one decode (:mod:`wallcli.batch.analyse`, wrapped for the
workers by :mod:`wallcli.batch.task`); which machines run the tasks is configuration
(:mod:`wallcli.batch.engine`: a Dask LocalCluster or an existing scheduler); the results file is
the run's memory (:mod:`wallcli.batch.results`), so a run can stop anywhere and resume.
"""
