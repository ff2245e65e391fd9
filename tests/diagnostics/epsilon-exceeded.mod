# Four H modules: one more than epsilon = 3 (paper Table 1). Reported at the fourth.
robot heavy {
    chain H1 - H4 - H3
        - H1   # expect: error[epsilon-exceeded]
        - L1
}
