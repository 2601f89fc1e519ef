"""mftstack: the Python side of mft-wbc (docs/reference/architecture.md "Python package").

  paths       the repository, built executables, configuration and runs folders (one place)
  processes   the supervised service processes: argv, start order, readiness, restart back-off, logs, stop
  registry    the one process registry: children bound to their parent's life, stopped by pid (mft-experiment)
  stackfile   multi-host stack files and their hosts
  ddsxml      the per-host DDS profiles of a stack file
  checks      everything checked before the first service starts
  summary     the run's summary: built, printed, written
  cli         mft-supervisor's commands (run, up, status, down, logs); services/mft-supervisor launches it
  errors      the supervisor's errors and one-line messages
  scripts     the measurement scripts' parser and one-line errors
  simlog      waiting on a running stack through its simulator's log (tests)
  testing     the one helper the tests run stacks with
"""
