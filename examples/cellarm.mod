# The environment statements (docs/language.md): an arm next to a shelf with one target.
robot cellarm {
    chain H1 - H4(pivot=-90deg) - L3(port=45deg)
    box shelf size (0.6, 0.4, 0.02) m at (0.3, 0, 0.25) m  # axis-aligned, centre position
    target p1 at (-0.24, -0.23, 0.585) m  # a position for tool0
}
