"""Entry points that saved scenes name: a checkpoint's PyRunner commands call
`yadebreak.coupling.engine.on_read`, `.on_zero`, `yadebreak.coupling.rolling.on_step` and
`yadebreak.coupling.bonded.on_step`. These modules forward to the engine (yadebreak.engine) and
stay for good, so that every saved scene resumes. New code imports yadebreak.engine."""
