# A 20 cm rubber cube (E = 1 MPa, nu = 0.3, 1000 kg/m^3) dropped from 30 cm onto the ground;
# its lowest point after 2 s.
import rapier_fvm as rf

world = rf.World(dt=1 / 60)
world.add_ground()
rubber = rf.Material("stable_neo_hookean", young=1e6, poisson=0.3, density=1000.0)
cube = world.add_soft_body(rf.Mesh.cuboid((0.1, 0.1, 0.1), (4, 4, 4)), rubber, translation=(0, 0.3, 0))
world.step(120)
print("lowest point (m):", world.positions(cube)[:, 1].min())
