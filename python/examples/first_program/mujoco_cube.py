# The same cube in MuJoCo: a flexcomp grid of 5 x 5 x 5 points with linear elasticity; the
# implicit `discrete` integrator is the one that takes flex elasticity. z is up.
import mujoco

xml = """
<mujoco>
  <option timestep="0.004" integrator="discrete" solver="Newton" iterations="1000"/>
  <worldbody>
    <geom type="plane" size="5 5 0.1"/>
    <flexcomp name="cube" type="grid" dim="3" dof="full" count="5 5 5" spacing="0.05 0.05 0.05"
              pos="0 0 0.3" mass="8" radius="0.002">
      <elasticity young="1e6" poisson="0.3" damping="0.01"/>
      <contact condim="3" selfcollide="none"/>
    </flexcomp>
  </worldbody>
</mujoco>"""
model = mujoco.MjModel.from_xml_string(xml)
data = mujoco.MjData(model)
while data.time < 2.0:
    mujoco.mj_step(model, data)
print("lowest point (m):", data.flexvert_xpos[:, 2].min())
