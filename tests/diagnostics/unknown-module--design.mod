design cell {
    target a at (0.3, 0, 0.2) m
    modules H1, L9   # expect: error[unknown-module] unknown module unit 'L9'
}
