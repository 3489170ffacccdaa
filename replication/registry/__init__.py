"""The reproduction registry: paper values, comparisons, the verdict rule, the register,
exports and the book helpers.  Knows no physics: imports nothing of nav/ or papers/.
"""
