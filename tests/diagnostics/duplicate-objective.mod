design cell {
    target a at (0.3, 0, 0.2) m
    rank modules, mass, modules   # expect: error[duplicate-objective] objective 'modules' is ranked twice in design 'cell'
}
