

def test_readable_drops_the_markup_and_keeps_the_words():
    from replication.registry.paper import readable

    assert readable(r"$\boldsymbol{\varepsilon}_b = C_G^b B \Omega U^{-1}(t_{n+1}, t_n)$") == (
        "ε_b = C_G^b B Ω U⁻¹(t_{n+1}, t_n)")
    assert readable(r"$$\frac{\phi_E(s)}{g_{dN}(s)} \approx \frac{1}{10} \quad (11)$$") == (
        "(φ_E(s))/(g_{dN}(s)) ≈ 1/10")
    assert readable(r"$\bar{\mathbf{A}}$ 为 12×12 状态矩阵") == "A\u0304 为 12×12 状态矩阵"
    assert readable(r"纬度为 $89.999\ 999\ 8^\circ$ 处") == "纬度为 89.999 999 8° 处"
