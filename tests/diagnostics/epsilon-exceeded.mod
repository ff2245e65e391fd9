# Four H modules: one more than epsilon = 3 (paper Table 1). Reported at the fourth.
robot heavy {
    chain H1 - H4 - H3
        - H1   # expect: error[epsilon-exceeded] 4 H modules exceed ε = 3 (paper rule 4, Table 1)
        - L1
}
