"""The process studies of a PA12 layer: energy density, bed temperature, sensitivities."""
