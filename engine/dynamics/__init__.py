"""Falling bodies (chapter: "Problème des contraintes non-pénétrables", "La solution ?", "Autre problème",
"La particule qui chute sur le sol", "Méthode de la Dichotomie", both "Application" slides)."""
