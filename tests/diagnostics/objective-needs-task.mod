# `rank cycle_time` times the cell's tasks: a design block without a task or path has none to time.
design cell {
    target a at (0.3, 0, 0.2) m
    rank cycle_time, mass   # expect: error[objective-needs-task] objective 'cycle_time' ranks the cell's tasks, but design 'cell' has no `task` and no `path`
}
