"""Wrong uses that mypy must reject with the stubs (python_stubs counts one error per line)."""
import dualgrid

dualgrid.preset(3)  # E: int for str
dualgrid.DynamicGrid(seed="1")  # E: str for int
dualgrid.CoSimulation("s.yaml", duration="long")  # E: str for float
x: str = dualgrid.CoSimulation("s.yaml").steps  # E: int to str
dualgrid.classify_cells([[0.1]], threshold="high")  # E: str for float
step: dualgrid.Step = dualgrid.CoSimulation("s.yaml").step()  # E: Optional[Step]
