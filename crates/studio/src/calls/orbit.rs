//! An orbit of the period map clicked on the page, streamed in chunks.

use super::*;

/// A click on the page: the orbit of the period map of `request`'s
/// declared settings ([`OrbitOptions`]), checked: its model has a period
/// map, the seed is a finite state of the right size.
pub fn orbit_check(
    catalog: Catalog,
    request: &AnalysisRequest,
) -> Result<(Plane, OrbitOptions), StudioError> {
    let (handle, params, options) = request.resolve::<OrbitOptions>(catalog)?;
    let method = (options.method.as_str(), options.tol);
    let plane = Plane::of(handle, params, options.axes, &options.through, method)?;
    if !plane.fast_phase {
        return Err(StudioError::Refused(Refusal::no_fast_phase(
            plane.info.name,
        )));
    }
    plane.seed(&options.seed)?;
    Ok((plane, options))
}

/// Points of an orbit projected on the page's axes (angles in [−π, π)), in
/// order: the first chunk starts with the seed.
#[derive(Clone, Debug, Serialize)]
pub struct OrbitChunk {
    pub points: Vec<[f64; 2]>,
}

/// How an orbit ended.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct OrbitEnd {
    /// Iterates computed (the seed not counted).
    pub periods: usize,
    /// The page went away (a superseded request): the orbit stopped early.
    pub cancelled: bool,
    pub f_evals: u64,
    pub seconds: f64,
    /// The orbit's tunes, one per degree of freedom: the fundamental
    /// frequency of its iterates (q_j + i p_j less the mean, q_j + i q_j′
    /// on constraints, e^{i q_j} for a circulating angle) in turns per
    /// period ([`mechlab_runtime::analysis::frequency_map::tunes`]); None for an
    /// orbit of fewer than 64 iterates or cancelled.
    pub tunes: Option<Vec<f64>>,
}

/// Iterates below which an orbit gets no tunes.
const MIN_TUNE_ITERATES: usize = 64;

/// How often a growing orbit is handed over.
const CHUNK_INTERVAL: Duration = Duration::from_millis(40);

const CHUNK_POINTS: usize = 4096;

/// Computes the orbit of `request`, handing its points to `sink` in chunks
/// as they come (at least every 40 ms); `sink` returns false when nobody
/// listens any more, which stops the orbit. An orbit that leaves the
/// model's domain ends with the integrator's error after the points before.
pub fn orbit(
    catalog: Catalog,
    request: &AnalysisRequest,
    sink: &mut dyn FnMut(OrbitChunk) -> bool,
) -> Result<OrbitEnd, StudioError> {
    let (setup, request) = orbit_check(catalog, request)?;
    let systems = mechlab_runtime::analysis::flows(setup.handle)?;
    // A constrained model's seed, on its constraints in the chart of the axes.
    let mut seed = request.seed.clone();
    systems
        .consistent(&setup.params, &mut seed, &setup.axes)
        .map_err(|e| StudioError::BadRequest {
            model: setup.info.name.into(),
            problem: RequestProblem::Inconsistent(e),
        })?;
    let started = Instant::now();
    let period = systems
        .phase_period(&setup.params)
        .ok_or_else(|| StudioError::Refused(Refusal::no_fast_phase(setup.info.name)))?;
    let system = systems.exact(&setup.params);
    let periodic = systems.periodic_state();
    let project = |y: &[f64]| {
        setup
            .axes
            .map(|a| if periodic[a] { wrap_angle(y[a]) } else { y[a] })
    };
    let mut integrator = Integrator::new(setup.method)?;
    let mut chunk = Vec::new();
    let mut states: Vec<Vec<f64>> = Vec::with_capacity(request.periods + 1);
    let mut last_sent = Instant::now();
    // The seed, then one per period.
    let (mut points, mut cancelled) = (0usize, false);
    let run = stream_orbit(
        &mut integrator,
        &*system,
        period,
        &seed,
        request.periods,
        &periodic,
        &mut |y| {
            chunk.push(project(y));
            states.push(y.to_vec());
            points += 1;
            if points > 1 && (chunk.len() >= CHUNK_POINTS || last_sent.elapsed() >= CHUNK_INTERVAL)
            {
                let points = std::mem::take(&mut chunk);
                cancelled = !sink(OrbitChunk { points });
                last_sent = Instant::now();
            }
            !cancelled
        },
    );
    let end = |periods, cancelled, integrator: &Integrator| OrbitEnd {
        periods,
        cancelled,
        f_evals: integrator.stats.f_evals,
        seconds: started.elapsed().as_secs_f64(),
        tunes: (!cancelled && states.len() >= MIN_TUNE_ITERATES)
            .then(|| mechlab_runtime::analysis::frequency_map::tunes(&states, &periodic).0),
    };
    if let Err(error) = run {
        // The points before the failure are the page's to keep.
        sink(OrbitChunk { points: chunk });
        return Err(
            match mechlab_runtime::domain::explain(setup.handle, &setup.params, &error) {
                Some(domain) => StudioError::OutsideDomain {
                    source: error,
                    domain: Box::new(domain),
                },
                None => error.into(),
            },
        );
    }
    if cancelled {
        return Ok(end(points - 1, true, &integrator));
    }
    let listening = chunk.is_empty() || sink(OrbitChunk { points: chunk });
    Ok(end(request.periods, !listening, &integrator))
}
