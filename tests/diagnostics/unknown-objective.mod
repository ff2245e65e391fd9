design cell {
    target a at (0.3, 0, 0.2) m
    rank mass, cost   # expect: error[unknown-objective] unknown objective 'cost'
}
